#include "tools/scene_setup.hpp"

#include <cmath>
#include <map>
#include <sstream>

#include "tools/cli_args.hpp"

namespace lidarloop {

StraightActor parse_actor(const std::string& spec) {
  const size_t comma = spec.find(',');
  const std::string type = spec.substr(0, comma);
  const auto t = actor_type_from_name(type);
  if (!t) throw InputError("--actor: unknown type '" + type + "' (expected one of: " + actor_type_names() + ")");
  const std::string rest = comma == std::string::npos ? "" : spec.substr(comma + 1);
  const size_t fields = std::count(rest.begin(), rest.end(), ',') + 1;
  if (fields != 3 && fields != 4) throw InputError("--actor: expected TYPE,X,Y,YAW_DEG[,SPEED], got '" + spec + "'");
  const auto v = parse_number_list(rest, fields, "--actor");
  return {*t, {v[0], v[1]}, v[2] * M_PI / 180, fields == 4 ? v[3] : 0.0};
}

static Eigen::Isometry3d actor_pose(const StraightActor& a, int64_t t_ns) {
  const Eigen::Vector2d heading(std::cos(a.yaw), std::sin(a.yaw));
  const Eigen::Vector2d p = a.start + heading * a.speed * double(t_ns) * 1e-9;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(p.x(), p.y(), 0));
  pose.rotate(Eigen::AngleAxisd(a.yaw, Eigen::Vector3d::UnitZ()));
  return pose;
}

SceneSetup make_scene(const std::string& world, const std::vector<StraightActor>& actors, int threads) {
  SceneSetup s{load_world(world), nullptr, actors, {}};
  s.scene = std::make_unique<RayScene>(s.world.world.mesh, threads);
  std::map<ActorType, int> prototypes;
  bool moving = false;
  for (const auto& a : actors) {
    if (!prototypes.count(a.type))
      prototypes[a.type] = s.scene->add_prototype(load_actor_mesh(actors_dir(), a.type, s.world.materials));
    s.scene->add_actor(prototypes[a.type], actor_pose(a, 0));
    moving = moving || a.speed != 0;
  }
  s.scene->commit();
  if (moving)
    s.actor_poses = [actors](int64_t t_ns, std::vector<Eigen::Isometry3d>& poses) {
      for (size_t i = 0; i < actors.size(); ++i) poses[i] = actor_pose(actors[i], t_ns);
    };
  return s;
}

std::unique_ptr<tbb::global_control> limit_threads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace lidarloop
