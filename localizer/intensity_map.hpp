#pragma once
// The intensity layer of the HD map (the paper's Fig. 9b, section 2.2.2): a grid over the local frame
// whose cells hold the count, mean and variance of the LiDAR intensities of the ground that fell in
// them, kept with the numerically stable running update of Eq. 8 (Welford's algorithm).
//
// On disk: a folder with `map.yaml` (origin, resolution, projection, tile size, world name and hash,
// build parameters, and the list of tiles) and `tiles/<ix>_<iy>.tile` files, each a fixed-size binary
// block of tile_cells x tile_cells cells with a checksum. Readers load tiles lazily and keep at most a
// bounded number in memory, so memory does not grow with the map.
#include <climits>
#include <cstdint>
#include <list>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"

namespace lidarloop {

struct IntensityCell {
  uint32_t count = 0;
  float mean = 0;
  float m2 = 0;  // sum of squared deviations from the mean (Welford); variance = m2 / count

  void add(double value);                  // Eq. 8
  void merge(const IntensityCell& other);  // Chan et al.'s pairwise combination
  double variance() const { return count > 0 ? double(m2) / double(count) : 0.0; }
};

// The same statistics in double precision: what a builder accumulates, so that a cell hit by many
// points is rounded to float once (when stored) instead of at every update. IntensityCell::add and
// ::merge run through these, so Eq. 8 and Chan's formula exist once.
struct IntensityMoments {
  uint32_t count = 0;
  double mean = 0;
  double m2 = 0;

  void add(double value);                     // Eq. 8 (Welford form)
  void merge(const IntensityMoments& other);  // Chan et al.
  double variance() const { return count > 0 ? m2 / double(count) : 0.0; }
  IntensityCell to_cell() const { return {count, float(mean), float(m2)}; }
  static IntensityMoments from_cell(const IntensityCell& c) { return {c.count, c.mean, c.m2}; }
};

struct IntensityMapHeader {
  std::string world;                         // world name
  std::string world_hash;                    // hex digest of what the map was built from
  Geodetic origin;                           // of the local frame (transverse Mercator, scale 1 on its meridian)
  double resolution_m = 0.2;                 // cell size
  int tile_cells = 320;                      // cells per tile side (64 m at 0.2 m)
  std::map<std::string, std::string> build;  // free-form build parameters, for people and cache keys
  std::vector<std::pair<int, int>> tiles;    // tile indices present on disk

  double tile_size_m() const { return resolution_m * tile_cells; }
};

// Tile index and cell-within-tile of a local point.
struct CellIndex {
  int tile_x, tile_y;
  int cell_x, cell_y;
};
CellIndex cell_index(const IntensityMapHeader& header, const Eigen::Vector2d& xy);

// Accumulates a map in memory (a mapping drive), then writes it.
class IntensityMapBuilder {
 public:
  explicit IntensityMapBuilder(IntensityMapHeader header);
  void add(const Eigen::Vector2d& xy, double intensity);
  // Chan's merge of every cell of `other`, which must have the same origin and resolution; its tiles may
  // be of another size (a small builder that holds only the blocks a part of a drive touched).
  void merge(const IntensityMapBuilder& other);
  std::optional<IntensityCell> cell(const Eigen::Vector2d& xy) const;
  // The header; its tile list is every tile made so far, handed over or not.
  const IntensityMapHeader& header() const { return header_; }
  size_t tile_count() const { return tiles_.size(); }  // held in memory
  // Hands over a finished tile and frees it: its cells, row-major (empty if the builder has none there).
  // A point or a merge that lands in it later is a logic error, and save() refuses a builder that handed
  // tiles over (an IntensityMapWriter writes them as they come).
  std::vector<IntensityMoments> take_tile(const std::pair<int, int>& key);
  // Writes map.yaml and the tiles into `dir` (created; an existing map there is replaced).
  void save(const std::string& dir) const;

 private:
  IntensityMapHeader header_;
  std::map<std::pair<int, int>, std::vector<IntensityMoments>> tiles_;  // row-major, y rows
  std::vector<std::pair<int, int>> taken_;                              // sorted
  // The tile of the previous point: a drive's points come in runs in one tile, and finding it in tiles_
  // is a fair share of an update. A copy (or move) of the builder starts without it: its pointer would
  // lead into the original.
  struct LastTile {
    std::pair<int, int> key{INT32_MIN, INT32_MIN};
    std::vector<IntensityMoments>* cells = nullptr;
    LastTile() = default;
    LastTile(const LastTile&) {}
    LastTile& operator=(const LastTile&) {
      key = {INT32_MIN, INT32_MIN}, cells = nullptr;
      return *this;
    }
  } last_;

  std::vector<IntensityMoments>& open_tile(const std::pair<int, int>& key);  // made if new; never a taken one
};

// Writes a map tile by tile, so that a builder can hand over the tiles it has finished and forget them:
// memory holds the tiles still open, not the map. Each tile file is written whole under a temporary
// name and renamed; map.yaml comes last, so the folder is a map only once finish() ran.
class IntensityMapWriter {
 public:
  // Creates `dir`; removes a map already there (its header first, then its tiles).
  explicit IntensityMapWriter(const std::string& dir);
  void write_tile(const IntensityMapHeader& header, const std::pair<int, int>& key,
                  const std::vector<IntensityMoments>& cells);
  // Writes map.yaml: `header` whose tile list must be exactly the tiles written.
  void finish(const IntensityMapHeader& header);

 private:
  std::string dir_;
  std::vector<std::pair<int, int>> written_;
};

// Reads a saved map lazily; throws InputError naming the file for a missing or corrupt header or
// tile, or one that does not match the header.
class IntensityMap {
 public:
  IntensityMap(const std::string& dir, size_t max_cached_tiles = 64);
  // The cache holds iterators into lru_: a copy would point into the original. Moving keeps them valid.
  IntensityMap(const IntensityMap&) = delete;
  IntensityMap& operator=(const IntensityMap&) = delete;
  IntensityMap(IntensityMap&&) = default;
  IntensityMap& operator=(IntensityMap&&) = default;
  const IntensityMapHeader& header() const { return header_; }
  // The cell at a local point, if the map has data there.
  std::optional<IntensityCell> cell(const Eigen::Vector2d& xy);
  // Reads the tiles the square of +-half_extent around `centre` touches into the cache now (at most as
  // many as it holds), so that the first lookups there do not pay for the disk; how many it holds.
  size_t preload(const Eigen::Vector2d& centre, double half_extent);
  size_t cached_tiles() const { return cache_.size(); }
  size_t tiles_loaded() const { return loads_; }  // how many tile reads so far

 private:
  const std::vector<IntensityCell>* tile(int tx, int ty);
  const std::vector<IntensityCell>* lookup_tile(const std::pair<int, int>& key);

  std::string dir_;
  IntensityMapHeader header_;
  size_t max_cached_;
  std::list<std::pair<int, int>> lru_;  // most recently used first
  std::map<std::pair<int, int>, std::pair<std::vector<IntensityCell>, std::list<std::pair<int, int>>::iterator>> cache_;
  std::map<std::pair<int, int>, bool> present_;
  size_t loads_ = 0;
  // The tile of the previous lookup: neighbouring queries nearly always hit it, and skipping the
  // cache's tree and LRU bookkeeping for them is most of a map lookup's cost (APS asks ~50 k a scan).
  std::pair<int, int> last_key_{INT32_MIN, INT32_MIN};
  const std::vector<IntensityCell>* last_tile_ = nullptr;
};

IntensityMapHeader read_intensity_map_header(const std::string& dir);

}  // namespace lidarloop
