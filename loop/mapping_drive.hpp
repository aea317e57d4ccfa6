#pragma once
// The mapping drive: a simulated car with ground-truth poses drives every lane of every road (both
// directions on two-way roads) and accumulates the intensities of ground returns into the intensity
// layer, as a survey vehicle does before a localizer can run.
#include <functional>
#include <string>

#include "localizer/intensity_map.hpp"
#include "sim/materials.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct MappingOptions {
  bool traffic = false;     // oncoming vehicles on the mapped roads (they raise cell variance)
  double speed = 15.0;      // m/s along each lane: 1.5 m between scans of 40 m reach
  double resolution = 0.2;  // m per cell
  int tile_cells = 320;     // 64 m tiles at 0.2 m
  // m above the carriageway: asphalt, paint, curbs and sidewalks, and the low parts of vehicles passing
  // by, which is how traffic raises the variance of the cells it crosses (paper, section 2.2.2).
  double max_ground_height = 0.5;
  double max_range = 40.0;  // m: farther ground returns are too sparse to help
  uint64_t seed = 1;

  std::string describe() const;  // the options as text, for the cache key and the map header
};

// `world_hash` identifies what the map is built from (see map_cache.hpp); it goes into the header.
IntensityMapBuilder run_mapping_drive(const WorldDescription& description, const World& world,
                                      const MaterialTable& materials, const std::string& actors_dir,
                                      const MappingOptions& options, const std::string& world_hash,
                                      const std::function<void(double fraction)>& progress = {});

}  // namespace lidarloop
