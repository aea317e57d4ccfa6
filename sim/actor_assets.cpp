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

std::string actor_type_names() {
  std::string out;
  for (const char* n : kNames) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

TriangleMesh load_actor_mesh(const std::string& actors_dir, ActorType type, const MaterialTable& materials) {
  return read_obj(actors_dir + "/" + actor_type_name(type) + ".obj", materials);
}

}  // namespace lidarloop
