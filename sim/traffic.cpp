#include "sim/traffic.hpp"

#include <cmath>

namespace lidarloop {

double actor_distance(const ActorPlan& plan, int64_t t_ns) {
  double s = plan.start_s;
  if (plan.speed <= 0 || t_ns <= plan.depart_ns) return s;
  double time = double(t_ns - plan.depart_ns) * 1e-9;
  for (const Wait& w : plan.waits) {
    if (w.at < s) continue;
    const double to_wait = (w.at - s) / plan.speed;
    if (time <= to_wait) return s + plan.speed * time;
    time -= to_wait;
    s = w.at;
    if (time <= w.duration_s) return s;
    time -= w.duration_s;
  }
  s += plan.speed * time;
  return plan.path.closed ? s : std::min(s, plan.path.length);
}

Pose2d actor_pose2d(const ActorPlan& plan, int64_t t_ns) { return plan.path.pose_at(actor_distance(plan, t_ns)); }

Eigen::Isometry3d actor_pose(const ActorPlan& plan, int64_t t_ns) {
  const Pose2d p = actor_pose2d(plan, t_ns);
  return Eigen::Translation3d(p.x, p.y, 0) * Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ());
}

}  // namespace lidarloop
