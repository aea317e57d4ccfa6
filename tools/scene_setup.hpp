#pragma once
// What `scan` and `bench lidar` share: a world in an Embree scene, with actors that drive straight.
#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "tools/world_assets.hpp"

namespace lidarloop {

struct StraightActor {
  ActorType type;
  Eigen::Vector2d start;  // footprint centre at t = 0
  double yaw = 0;         // rad
  double speed = 0;       // m/s along yaw
};
// "TYPE,X,Y,YAW_DEG[,SPEED]"
StraightActor parse_actor(const std::string& spec);

struct SceneSetup {
  LoadedWorld world;
  std::unique_ptr<RayScene> scene;
  std::vector<StraightActor> actors;
  ActorPoses actor_poses;  // empty when no actor moves
};
SceneSetup make_scene(const std::string& world, const std::vector<StraightActor>& actors, int threads);

// Limits TBB (our loops) to `threads` for as long as it lives.
std::unique_ptr<tbb::global_control> limit_threads(int threads);

}  // namespace lidarloop
