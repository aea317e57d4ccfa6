#include "localizer/deskew.hpp"

#include <cmath>

namespace lidarloop {

constexpr double kStraight = 1e-9;  // rad/s: below this the arc is a straight line

// The vehicle's pose at time t relative to time 0, driving an arc of constant speed and yaw rate.
static Eigen::Isometry3d arc_pose(const ScanMotion& m, double t) {
  const double yaw = m.yaw_rate * t;
  const bool straight = std::abs(m.yaw_rate) < kStraight;
  const double x = straight ? m.speed * t : m.speed / m.yaw_rate * std::sin(yaw);
  const double y = straight ? 0.0 : m.speed / m.yaw_rate * (1 - std::cos(yaw));
  return Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

std::vector<Eigen::Vector3d> deskew(const PointCloud& cloud, const Eigen::Isometry3d& mount, const ScanMotion& motion,
                                    int64_t reference_ns) {
  const Eigen::Isometry3d reference_inverse = arc_pose(motion, double(reference_ns) * 1e-9).inverse();
  std::vector<Eigen::Vector3d> out;
  out.reserve(cloud.points.size());
  uint32_t last_t = UINT32_MAX;
  Eigen::Isometry3d to_reference = Eigen::Isometry3d::Identity();
  for (const LidarPoint& p : cloud.points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    if (!q.allFinite()) continue;
    if (p.t_ns != last_t) {  // points come in firing order: one pose per firing time
      to_reference = reference_inverse * arc_pose(motion, double(p.t_ns) * 1e-9) * mount;
      last_t = p.t_ns;
    }
    out.push_back(to_reference * q);
  }
  return out;
}

std::vector<Eigen::Vector3d> to_vehicle_frame(const PointCloud& cloud, const Eigen::Isometry3d& mount) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(cloud.points.size());
  for (const LidarPoint& p : cloud.points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    if (q.allFinite()) out.push_back(mount * q);
  }
  return out;
}

}  // namespace lidarloop
