#include "sim/traffic.hpp"

#include <cmath>
#include <map>
#include <optional>

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

Eigen::Isometry3d actor_pose(const ActorPlan& plan, int64_t t_ns, const GroundHeight& ground) {
  Eigen::Isometry3d pose = to_isometry(actor_pose2d(plan, t_ns));
  if (ground) pose.translation().z() = ground(pose.translation().head<2>());
  return pose;
}

void add_actors(RayScene& scene, const std::vector<ActorPlan>& actors, const std::string& actors_dir,
                const MaterialTable& materials, const GroundHeight& ground) {
  std::map<ActorType, int> prototypes;  // one BVH per actor type, instanced for every actor of it
  for (const auto& a : actors) {
    if (!prototypes.count(a.type))
      prototypes[a.type] = scene.add_prototype(load_actor_mesh(actors_dir, a.type, materials));
    scene.add_actor(prototypes[a.type], actor_pose(a, 0, ground));
  }
  scene.commit();
}

ActorPoses actor_motion(std::vector<ActorPlan> actors, GroundHeight ground) {
  bool moving = false;
  for (const auto& a : actors) moving = moving || a.speed > 0;
  if (!moving) return {};
  // A parked actor's pose is worked out once: the ground under it is a point-in-polygon test against the
  // whole carriageway, which, asked for hundreds of parked cars at every keyframe of every scan, was
  // most of a busy street's simulation time.
  std::vector<std::optional<Eigen::Isometry3d>> parked(actors.size());
  for (size_t i = 0; i < actors.size(); ++i)
    if (actors[i].speed <= 0) parked[i] = actor_pose(actors[i], 0, ground);
  return [actors = std::move(actors), ground = std::move(ground), parked = std::move(parked)](
             int64_t t_ns, std::vector<Eigen::Isometry3d>& poses) {
    for (size_t i = 0; i < actors.size(); ++i) poses[i] = parked[i] ? *parked[i] : actor_pose(actors[i], t_ns, ground);
  };
}

}  // namespace lidarloop
