#include "localizer/deskew.hpp"

#include <cmath>

namespace lidarloop {

constexpr double kStraight = 1e-9;  // rad/s: below this the arc is a straight line
// Points fired within this much of each other share one pose. Every firing has its own time, and one
// pose per point cost 4 ms a scan; 50 us is 0.5 mm of travel at 10 m/s, a twentieth of the range noise.
constexpr uint32_t kPoseStepNs = 50'000;

// The vehicle's pose at time t relative to time 0, driving an arc of constant speed and yaw rate.
static Eigen::Isometry3d arc_pose(const ScanMotion& m, double t) {
  const double yaw = m.yaw_rate * t;
  const bool straight = std::abs(m.yaw_rate) < kStraight;
  const double x = straight ? m.speed * t : m.speed / m.yaw_rate * std::sin(yaw);
  const double y = straight ? 0.0 : m.speed / m.yaw_rate * (1 - std::cos(yaw));
  return Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

// Room for every point of the cloud, written in place and cut to the points kept at the end: that
// spares a scan's hundred thousand push_backs (each a capacity check, three times).
static void resize(ScanPoints& s, size_t n) {
  s.xyz.resize(n);
  s.ring.resize(n);
  s.intensity.resize(n);
}

static void put(ScanPoints& s, size_t k, const Eigen::Vector3d& xyz, const LidarPoint& p) {
  s.xyz[k] = xyz;
  s.ring[k] = p.ring;
  s.intensity[k] = p.intensity;
}

ScanPoints deskew(const PointCloud& cloud, const Eigen::Isometry3d& mount, const ScanMotion& motion,
                  int64_t reference_ns) {
  const Eigen::Isometry3d reference_inverse = arc_pose(motion, double(reference_ns) * 1e-9).inverse();
  ScanPoints out;
  resize(out, cloud.points.size());
  size_t kept = 0;
  uint32_t last_step = UINT32_MAX;
  Eigen::Isometry3d to_reference = Eigen::Isometry3d::Identity();
  for (const LidarPoint& p : cloud.points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    if (!q.allFinite()) {
      ++out.dropped;
      continue;
    }
    if (p.t_ns / kPoseStepNs != last_step) {  // points come in firing order
      last_step = p.t_ns / kPoseStepNs;
      const double t = (double(last_step) + 0.5) * double(kPoseStepNs) * 1e-9;  // the step's middle
      to_reference = reference_inverse * arc_pose(motion, t) * mount;
    }
    put(out, kept++, to_reference * q, p);
  }
  resize(out, kept);  // the points kept
  return out;
}

ScanPoints to_vehicle_frame(const PointCloud& cloud, const Eigen::Isometry3d& mount) {
  ScanPoints out;
  resize(out, cloud.points.size());
  size_t kept = 0;
  for (const LidarPoint& p : cloud.points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    if (q.allFinite())
      put(out, kept++, mount * q, p);
    else
      ++out.dropped;
  }
  resize(out, kept);  // the points kept
  return out;
}

}  // namespace lidarloop
