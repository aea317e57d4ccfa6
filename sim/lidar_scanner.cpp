#include "sim/lidar_scanner.hpp"
#include "common/units.hpp"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lidarloop {

PoseAt constant_twist(const Eigen::Isometry3d& start, int64_t t0_ns, double v, double w) {
  return [=](int64_t t_ns) {
    const double t = double(t_ns - t0_ns) * 1e-9;
    const double yaw = w * t;
    // Exact integration of the unicycle: a straight line when w = 0, an arc otherwise.
    const double ds = std::abs(w) < 1e-9 ? v * t : v / w * std::sin(yaw);
    const double dl = std::abs(w) < 1e-9 ? 0.0 : v / w * (1 - std::cos(yaw));
    Eigen::Isometry3d pose = start;
    pose.translate(Eigen::Vector3d(ds, dl, 0));
    pose.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    return pose;
  };
}

LidarScanner::LidarScanner(const Hdl32eConfig& config, const MaterialTable& materials)
    : config_(config), returns_(config), mount_(config.mount()) {
  for (size_t i = 0; i < materials.size(); ++i) materials_.push_back(materials[MaterialId(i)]);
  // The head spins clockwise seen from above (yaw decreasing in the x-forward, y-left frame).
  const double yaw_rate = -2 * M_PI * config.rotation_hz;
  for (int slot = 0; slot < kHdl32eLasers; ++slot) {
    const double elevation = config.elevation_deg[config.firing_order[slot]] * kDeg;
    const double yaw = yaw_rate * double(slot * config.firing_period_ns) * 1e-9;
    slot_direction_[slot] = Eigen::Vector3f(float(std::cos(elevation) * std::cos(yaw)),
                                            float(std::cos(elevation) * std::sin(yaw)), float(std::sin(elevation)));
  }
  const int cycles = config.cycles_per_scan();
  const int per_keyframe =
      std::max(config.cycles_per_actor_update, (cycles + RayScene::kMaxKeyframes - 2) / (RayScene::kMaxKeyframes - 1));
  keyframes_ = (cycles + per_keyframe - 1) / per_keyframe + 1;
  keyframe_step_ns_ = per_keyframe * config.cycle_period_ns();
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const double yaw = config.scan_start_yaw_deg * kDeg + yaw_rate * double(config.firing_time_ns(cycle, 0)) * 1e-9;
    cycle_yaw_.emplace_back(float(std::cos(yaw)), float(std::sin(yaw)));
  }
}

std::vector<LidarScanner::CyclePose> LidarScanner::cycle_poses(const PoseAt& vehicle_pose, int64_t stamp_ns) const {
  const int cycles = config_.cycles_per_scan();
  std::vector<CyclePose> poses(cycles);
  auto sensor_at = [&](int64_t t) { return vehicle_pose(t) * mount_; };
  if (!config_.motion_distortion) {
    const Eigen::Isometry3d p = sensor_at(stamp_ns);
    for (auto& c : poses) c = {p.linear().cast<float>(), p.translation().cast<float>(), Eigen::Vector3f::Zero()};
    return poses;
  }
  const double dt = double(config_.cycle_period_ns()) * 1e-9;
  Eigen::Isometry3d next = sensor_at(stamp_ns);
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const Eigen::Isometry3d now = next;
    next = sensor_at(stamp_ns + config_.firing_time_ns(cycle + 1, 0));
    poses[cycle] = {now.linear().cast<float>(), now.translation().cast<float>(),
                    ((next.translation() - now.translation()) / dt).cast<float>()};
  }
  return poses;
}

Eigen::Vector3f LidarScanner::sensor_direction(int cycle, int slot) const {
  const Eigen::Vector2f& cs = cycle_yaw_[cycle];
  const Eigen::Vector3f& d = slot_direction_[slot];
  return {cs.x() * d.x() - cs.y() * d.y(), cs.y() * d.x() + cs.x() * d.y(), d.z()};
}

LidarRay LidarScanner::ray(const CyclePose& pose, int cycle, int slot) const {
  const float dt = float(double(slot * config_.firing_period_ns) * 1e-9);
  const double time = double(config_.firing_time_ns(cycle, slot)) / double((keyframes_ - 1) * keyframe_step_ns_);
  return {pose.origin + pose.velocity * dt, pose.rotation * sensor_direction(cycle, slot), float(time)};
}

std::vector<LidarRay> LidarScanner::rays(const PoseAt& vehicle_pose, int64_t stamp_ns) const {
  const auto poses = cycle_poses(vehicle_pose, stamp_ns);
  std::vector<LidarRay> out;
  out.reserve(size_t(rays_per_scan()));
  for (int cycle = 0; cycle < int(poses.size()); ++cycle)
    for (int slot = 0; slot < kHdl32eLasers; ++slot) out.push_back(ray(poses[cycle], cycle, slot));
  return out;
}

PointCloud LidarScanner::scan(RayScene& scene, const PoseAt& vehicle_pose, int64_t stamp_ns, uint64_t seed,
                              const ActorPoses& actor_poses) const {
  const auto poses = cycle_poses(vehicle_pose, stamp_ns);
  const int cycles = int(poses.size());
  const CounterRng rng(seed, uint64_t(stamp_ns));
  std::vector<LidarPoint> points(size_t(cycles) * kHdl32eLasers);
  std::vector<uint8_t> valid(points.size(), 0);
  const float tnear = float(config_.min_range_m) * 0.5f, tfar = float(config_.max_range_m) * 1.05f;

  // Rays travel in packets of the same laser over consecutive cycles: nearly parallel, so Embree's
  // packet traversal visits almost the same nodes for all of them.
  constexpr int kPacket = RayScene::kPacket;
  auto cast = [&](int first_cycle, int end_cycle) {
    const int groups = (end_cycle - first_cycle + kPacket - 1) / kPacket;
    tbb::parallel_for(tbb::blocked_range<int>(0, groups * kHdl32eLasers, 8), [&](const tbb::blocked_range<int>& range) {
      LidarRay rays[kPacket];
      RayHit hits[kPacket];
      bool found[kPacket];
      for (int packet = range.begin(); packet != range.end(); ++packet) {
        const int slot = packet % kHdl32eLasers, cycle0 = first_cycle + (packet / kHdl32eLasers) * kPacket;
        const int count = std::min(kPacket, end_cycle - cycle0);
        for (int k = 0; k < count; ++k) rays[k] = ray(poses[cycle0 + k], cycle0 + k, slot);
        scene.intersect8(rays, count, tnear, tfar, hits, found);
        const int ring = config_.firing_order[slot];
        for (int k = 0; k < count; ++k) {
          if (!found[k]) continue;
          const int cycle = cycle0 + k;
          const size_t i = size_t(cycle) * kHdl32eLasers + size_t(slot);
          const double cos_incidence = std::abs(double(hits[k].normal.dot(rays[k].direction)));
          const auto ret = returns_(materials_[hits[k].material], hits[k].range, cos_incidence, ring, rng, i);
          if (!ret) continue;
          const Eigen::Vector3f p = sensor_direction(cycle, slot) * ret->range;
          points[i] = {p.x(),          p.y(),          p.z(),
                       ret->intensity, uint16_t(ring), uint32_t(config_.firing_time_ns(cycle, slot))};
          valid[i] = 1;
        }
      }
    });
  };

  if (actor_poses && scene.actor_count() > 0) {
    std::vector<std::vector<Eigen::Isometry3d>> motion(scene.actor_count());
    std::vector<Eigen::Isometry3d> poses(scene.actor_count());
    for (int k = 0; k < keyframes_; ++k) {
      actor_poses(stamp_ns + k * keyframe_step_ns_, poses);
      for (size_t a = 0; a < poses.size(); ++a) motion[a].push_back(poses[a]);
    }
    for (size_t a = 0; a < motion.size(); ++a) scene.set_actor_motion(int(a), motion[a]);
    scene.commit();
  }
  cast(0, cycles);

  PointCloud cloud;
  cloud.stamp_ns = stamp_ns;
  cloud.points.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    if (valid[i]) cloud.points.push_back(points[i]);
  return cloud;
}

}  // namespace lidarloop
