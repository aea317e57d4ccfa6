#pragma once
// A top view of a generated world for people: every triangle filled with its material's colour, drawn
// from the lowest to the highest so roofs and crowns cover what is under them; curbs in green.
#include <string>

#include "sim/materials.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

void write_world_map_png(const std::string& path, const World& world, const MaterialTable& materials,
                         double metres_per_pixel);

}  // namespace lidarloop
