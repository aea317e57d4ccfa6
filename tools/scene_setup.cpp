#include "tools/scene_setup.hpp"

#include <cmath>
#include <sstream>

#include "tools/cli_args.hpp"

namespace lidarloop {

ActorPlan straight_actor(ActorType type, const Eigen::Vector2d& start, double yaw, double speed) {
  constexpr double kFar = 1e5;  // m of straight road ahead: more than any run drives
  ActorPlan a;
  a.type = type;
  a.name = actor_type_name(type);
  a.path = make_path({start, start + Eigen::Vector2d(std::cos(yaw), std::sin(yaw)) * kFar}, false);
  a.speed = speed;
  return a;
}

ActorPlan parse_actor(const std::string& spec) {
  const size_t comma = spec.find(',');
  const std::string type = spec.substr(0, comma);
  const auto t = actor_type_from_name(type);
  if (!t) throw InputError("--actor: unknown type '" + type + "' (expected one of: " + actor_type_names() + ")");
  const std::string rest = comma == std::string::npos ? "" : spec.substr(comma + 1);
  const size_t fields = std::count(rest.begin(), rest.end(), ',') + 1;
  if (fields != 3 && fields != 4) throw InputError("--actor: expected TYPE,X,Y,YAW_DEG[,SPEED], got '" + spec + "'");
  const auto v = parse_number_list(rest, fields, "--actor");
  return straight_actor(*t, {v[0], v[1]}, v[2] * M_PI / 180, fields == 4 ? v[3] : 0.0);
}

std::unique_ptr<RayScene> ray_scene(const LoadedWorld& world, const std::vector<ActorPlan>& actors, int threads,
                                    const std::string& isa) {
  auto scene = std::make_unique<RayScene>(world.world.mesh, threads, RayScene::MeshBuffers::copied, isa);
  add_actors(*scene, actors, actors_dir(), world.materials);
  return scene;
}

SceneSetup make_scene(const std::string& world, const std::vector<ActorPlan>& actors, int threads) {
  SceneSetup s{load_world(world), nullptr, actors, {}};
  s.scene = ray_scene(s.world, actors, threads);
  s.actor_poses = actor_motion(actors);
  return s;
}

std::unique_ptr<tbb::global_control> limit_threads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace lidarloop
