#pragma once
// A top view of a generated world for people: every triangle filled with its material's colour, drawn
// from the lowest to the highest so roofs and crowns cover what is under them; curb lines coloured by
// kind (vertical, sloped, rolled; cut for a ramp, a driveway, or flush) with a key in the corner.
#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sim/materials.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct MapOverlay {
  Polyline2d line;
  std::array<uint8_t, 3> bgr{0, 0, 255};
  int thickness = 2;
};

// The colour (BGR) a curb line of `kind` is drawn in.
cv::Scalar curb_colour(const std::string& kind);

void write_world_map_png(const std::string& path, const World& world, const MaterialTable& materials,
                         double metres_per_pixel, const std::vector<MapOverlay>& overlays = {});

}  // namespace lidarloop
