#pragma once
// The HD map a localizer loads: the curb layer and the intensity layer of one world, from a map folder
// (map.yaml, tiles/, curbs.geojson) as `lidarloop map` writes it. Opening checks that both layers
// belong together and to the world the caller expects. The point-cloud layer (points.yaml, points/)
// is there in maps of format 5 and later; only the gicp method needs it.
#include <optional>
#include <string>

#include "localizer/curb_layer.hpp"
#include "localizer/intensity_map.hpp"
#include "localizer/point_map.hpp"

namespace lidarloop {

struct HdMap {
  CurbLayer curbs;
  IntensityMap intensity;
  std::optional<PointMap> points;  // absent in a folder without points.yaml
};

// Throws InputError naming the file when a layer is missing or corrupt, when the layers disagree
// (world, origin), or when the map is of another world than `expected_world` (if not empty).
HdMap open_hd_map(const std::string& dir, const std::string& expected_world = "", size_t max_cached_tiles = 16);

}  // namespace lidarloop
