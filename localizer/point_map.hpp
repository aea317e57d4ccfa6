#pragma once
// The point-cloud layer of the HD map (beyond the paper; what the `gicp` method registers scans
// against): the survey's de-skewed scans, placed with the survey pose, voxel-downsampled to one point
// per voxel (the centroid of the points that fell in it), in square tiles of the same size and grid
// as the intensity layer's, so the mapping drive finishes both layers' tiles together and a
// localizer loads only the tiles around the car.
//
// On disk, beside the intensity layer: `points.yaml` (format, version, world and hash, voxel size,
// tile size, the list of tiles) and `points/<ix>_<iy>.pts`, each little-endian:
//   magic 'LLPC' | u32 version (1) | i32 tile_x | i32 tile_y | u32 point count n |
//   n x (f32 x, f32 y, f32 z: local metres) | u32 CRC-32 of every byte before it
// Points are in voxel order (by x, then y, then z index), so a map's bytes depend only on its points.
// float keeps 0.1 mm at 2 km from the origin, far below the voxel size.
#include <cstdint>
#include <list>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

struct PointMapHeader {
  std::string world, world_hash;
  double voxel_m = 0.4;
  int tile_voxels = 160;                   // voxels per tile side (64 m at 0.4 m, the intensity tiles)
  std::vector<std::pair<int, int>> tiles;  // present on disk, sorted

  double tile_size_m() const { return voxel_m * tile_voxels; }
};

// Accumulates voxel centroids (a mapping drive, or a part of one), then hands tiles over.
class PointMapBuilder {
 public:
  explicit PointMapBuilder(PointMapHeader header);
  // Movable, not copyable: it remembers the voxel of the previous point (a node that moves with it).
  PointMapBuilder(const PointMapBuilder&) = delete;
  PointMapBuilder& operator=(const PointMapBuilder&) = delete;
  PointMapBuilder(PointMapBuilder&&) = default;
  PointMapBuilder& operator=(PointMapBuilder&&) = default;
  void add(const Eigen::Vector3d& p);  // non-finite points are not measurements: ignored
  // Adds every voxel of `other` (same voxel size and tiling). Sums are added in merge order, so a
  // fixed order of merges gives the same centroids to the last bit.
  void merge(const PointMapBuilder& other);
  // The header; its tile list is every tile made so far.
  const PointMapHeader& header() const { return header_; }
  // Hands over a finished tile and frees it: its centroids in voxel order (empty if none there).
  std::vector<Eigen::Vector3f> take_tile(const std::pair<int, int>& key);
  size_t voxel_count() const;  // held in memory

 private:
  // Offsets from the voxel's corner are summed, in float: small numbers keep float's precision.
  struct Sum {
    float x = 0, y = 0, z = 0;
    uint32_t count = 0;
  };
  using Tile = std::unordered_map<uint64_t, Sum>;  // by packed global voxel index
  PointMapHeader header_;
  std::map<std::pair<int, int>, Tile> tiles_;
  std::set<std::pair<int, int>> taken_;
  // The voxel of the previous point: a ring's neighbouring returns often share one, and the hash
  // lookup is most of an update's cost.
  uint64_t last_index_ = 0;
  Sum* last_sum_ = nullptr;
  Tile& open_tile(const std::pair<int, int>& key);
};

// Writes tiles as they come (each whole, under a temporary name, then renamed) and the header last.
class PointMapWriter {
 public:
  explicit PointMapWriter(const std::string& dir);  // the map folder; makes points/ in it
  void write_tile(const std::pair<int, int>& key, const std::vector<Eigen::Vector3f>& points);
  // Writes points.yaml: `header` with the tiles written as its tile list (a tile with no points is not
  // written; every tile written must be one of the header's).
  void finish(const PointMapHeader& header);

 private:
  std::string dir_;
  std::set<std::pair<int, int>> written_;
};

// Reads points.yaml; InputError naming the file if it is missing or wrong.
PointMapHeader read_point_map_header(const std::string& dir);
bool has_point_map(const std::string& dir);
// One tile file, checked; InputError naming the file for a missing, truncated or corrupt one.
std::vector<Eigen::Vector3f> read_point_tile(const std::string& file, const std::pair<int, int>& key);
std::string point_tile_file(const std::string& dir, const std::pair<int, int>& key);

// Reads a saved layer lazily, keeping at most a bounded number of tiles in memory.
class PointMap {
 public:
  PointMap(const std::string& dir, size_t max_cached_tiles = 16);
  const PointMapHeader& header() const { return header_; }
  // The map's points within `radius` (horizontally) of `centre`, in tile order.
  std::vector<Eigen::Vector3d> points_near(const Eigen::Vector2d& centre, double radius);
  size_t tiles_loaded() const { return loads_; }

 private:
  const std::vector<Eigen::Vector3f>& tile(const std::pair<int, int>& key);
  std::string dir_;
  PointMapHeader header_;
  std::set<std::pair<int, int>> present_;
  size_t max_cached_;
  std::list<std::pair<int, int>> lru_;  // most recently used first
  std::map<std::pair<int, int>, std::vector<Eigen::Vector3f>> cache_;
  size_t loads_ = 0;
};

}  // namespace lidarloop
