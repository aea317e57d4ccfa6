#pragma once
// Traffic actors: cars, buses, trucks, pedestrians and cyclists moving along paths with a speed,
// a start time and waits, or parked. Their pose is a pure function of time, so a scan can ask where
// each one was at any firing.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/vehicle_messages.hpp"
#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/path.hpp"
#include "sim/road_surface.hpp"

namespace lidarloop {

struct Wait {
  double at = 0;  // arc length along the path, m
  double duration_s = 0;
};

struct ActorPlan {
  std::string name;  // for logs: "<type>_<index>"
  ActorType type = ActorType::car;
  Path path;                // a parked actor has a one-point path at its position
  double start_s = 0;       // arc length where it stands at t = 0, m
  double speed = 0;         // m/s; 0 = parked
  int64_t depart_ns = 0;    // when it starts moving
  std::vector<Wait> waits;  // sorted by `at`
};

// Arc length travelled along the path by time t (waits included, clamped at the end of an open path).
double actor_distance(const ActorPlan& plan, int64_t t_ns);
Pose2d actor_pose2d(const ActorPlan& plan, int64_t t_ns);
// Footprint centre on the ground (at z = 0 without one).
Eigen::Isometry3d actor_pose(const ActorPlan& plan, int64_t t_ns, const GroundHeight& ground = {});

// Puts the actors into the scene (one BVH per actor type, an instance per actor, at their t = 0 poses)
// and commits it.
void add_actors(RayScene& scene, const std::vector<ActorPlan>& actors, const std::string& actors_dir,
                const MaterialTable& materials, const GroundHeight& ground = {});
// Where those actors are at any time, in the order added: what the scanner asks while casting.
// Empty when none of them moves.
ActorPoses actor_motion(std::vector<ActorPlan> actors, GroundHeight ground = {});

}  // namespace lidarloop
