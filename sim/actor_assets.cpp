#include "sim/actor_assets.hpp"

#include <array>

#include "sim/obj_file.hpp"

namespace lidarloop {

static constexpr std::array<const char*, 5> kNames = {"car", "bus", "truck", "pedestrian", "cyclist"};

std::optional<ActorType> actor_type_from_name(const std::string& name) {
  for (size_t i = 0; i < kNames.size(); ++i)
    if (name == kNames[i]) return static_cast<ActorType>(i);
  return std::nullopt;
}

std::string actor_type_name(ActorType type) { return kNames[static_cast<size_t>(type)]; }

ActorFootprint actor_footprint(ActorType type) {
  switch (type) {
    case ActorType::car:
      return {4.612, 1.85};
    case ActorType::bus:
      return {12.012, 2.562};
    case ActorType::truck:
      return {8.512, 2.512};
    case ActorType::pedestrian:
      return {0.766, 0.501};
    case ActorType::cyclist:
      return {1.75, 0.6};
  }
  return {0, 0};
}

std::string actor_type_names() {
  std::string out;
  for (const char* n : kNames) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

TriangleMesh load_actor_mesh(const std::string& actors_dir, ActorType type, const MaterialTable& materials) {
  return read_obj(actors_dir + "/" + actor_type_name(type) + ".obj", materials);
}

}  // namespace lidarloop
