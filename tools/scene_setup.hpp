#pragma once
// What `scan` and `bench lidar` share: a world in an Embree scene, with actors that drive straight.
#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/ray_scene.hpp"
#include "sim/traffic.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {

// An actor driving straight on from `start` (footprint centre at t = 0) along `yaw` at `speed`.
ActorPlan straight_actor(ActorType type, const Eigen::Vector2d& start, double yaw, double speed);
// "TYPE,X,Y,YAW_DEG[,SPEED]"
ActorPlan parse_actor(const std::string& spec);

struct SceneSetup {
  LoadedWorld world;
  std::unique_ptr<RayScene> scene;
  std::vector<ActorPlan> actors;
  ActorPoses actor_poses;  // empty when no actor moves
};
SceneSetup make_scene(const std::string& world, const std::vector<ActorPlan>& actors, int threads);
// A loaded world and its actors as a ray scene, cast with the kernels `isa` (a benchmark's peer).
std::unique_ptr<RayScene> ray_scene(const LoadedWorld& world, const std::vector<ActorPlan>& actors, int threads,
                                    const std::string& isa = ray_isa());

// Limits TBB (our loops) to `threads` for as long as it lives.
std::unique_ptr<tbb::global_control> limit_threads(int threads);

}  // namespace lidarloop
