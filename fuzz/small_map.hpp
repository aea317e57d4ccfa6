#pragma once
// A small but complete HD map folder written by the project's own writers (the layers `lidarloop map`
// writes: map.yaml + tiles/, points.yaml + points/, curbs.geojson), with tiles of a few cells so that
// every file of it is a short fuzz input. The map target replaces one of its files by the fuzz input.
#include <string>
#include <utility>
#include <vector>

#include "common/curb_map_file.hpp"
#include "localizer/intensity_map.hpp"
#include "localizer/point_map.hpp"

namespace lidarloop::fuzz {

inline constexpr const char* kSmallMapWorld = "fuzz";
// Two tiles of 8 x 8 cells of 0.5 m side by side, so a query can cross from one tile to the next.
inline constexpr int kSmallTileCells = 8;  // the smallest tile the map formats allow
inline constexpr double kSmallResolutionM = 0.5;
inline const std::vector<std::pair<int, int>> kSmallTiles = {{0, 0}, {1, 0}};

inline void write_small_map(const std::string& dir) {
  const Geodetic origin{31.2856, 121.2147, 4.0};
  IntensityMapHeader header;
  header.world = kSmallMapWorld;
  header.world_hash = "0123456789abcdef";
  header.origin = origin;
  header.resolution_m = kSmallResolutionM;
  header.tile_cells = kSmallTileCells;
  IntensityMapBuilder intensity(header);
  PointMapHeader point_header{kSmallMapWorld, header.world_hash, kSmallResolutionM, kSmallTileCells, {}};
  PointMapBuilder points(point_header);
  for (int i = 0; i < 2 * kSmallTileCells; ++i)
    for (int j = 0; j < kSmallTileCells; ++j) {
      const Eigen::Vector2d xy = (Eigen::Vector2d(i, j) + Eigen::Vector2d(0.5, 0.5)) * kSmallResolutionM;
      intensity.add(xy, 10.0 + i + j);
      points.add({xy.x(), xy.y(), 0.1 * j});
    }
  intensity.save(dir);
  PointMapWriter point_writer(dir);
  for (const auto& key : kSmallTiles) point_writer.write_tile(key, points.take_tile(key));
  point_writer.finish(points.header());
  CurbMap curbs{
      origin, kSmallMapWorld, {{{0.0, 0.2}, {4.0, 0.2}}, {{0.0, 1.8}, {2.0, 1.9}, {4.0, 1.8}}}, {"vertical", "sloped"}};
  write_curb_map(dir + "/curbs.geojson", curbs);
}

// The files of the small map a fuzz input can stand in for, by the input's first byte.
inline const std::vector<std::string>& small_map_files() {
  static const std::vector<std::string> files = {"map.yaml", "tiles/0_0.tile", "points.yaml", "points/0_0.pts",
                                                 "curbs.geojson"};
  return files;
}

}  // namespace lidarloop::fuzz
