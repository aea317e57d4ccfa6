#pragma once
// The traffic actor types and their meshes in assets/actors/ (frame: x forward, y left, z up, origin at
// the footprint centre on the ground).
#include <optional>
#include <string>

#include "sim/materials.hpp"
#include "sim/triangle_mesh.hpp"

namespace lidarloop {

enum class ActorType { car, bus, truck, pedestrian, cyclist };

std::optional<ActorType> actor_type_from_name(const std::string& name);
std::string actor_type_name(ActorType type);
std::string actor_type_names();  // "car, bus, truck, pedestrian, cyclist"

// The footprint of each type's mesh (assets/actors/README.md), for placing actors beside a curb without
// loading the meshes: length along x and width along y, m.
struct ActorFootprint {
  double length, width;
};
ActorFootprint actor_footprint(ActorType type);
TriangleMesh load_actor_mesh(const std::string& actors_dir, ActorType type, const MaterialTable& materials);

}  // namespace lidarloop
