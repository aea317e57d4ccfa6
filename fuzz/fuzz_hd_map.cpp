// An HD map folder as a localizer opens it (open_hd_map) and reads it lazily: the input's first byte
// picks one file of a small, valid map (fuzz/small_map.hpp: a layer header, a tile, the curbs), the rest
// of the input replaces that file's bytes, and every tile is then asked for.
#include <map>
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "fuzz/small_map.hpp"
#include "localizer/hd_map.hpp"
#include "localizer/map_files.hpp"

namespace {
using namespace lidarloop;

// The small map's folder and each file's original bytes, to put back after an input replaced it.
struct SmallMap {
  std::string dir = (fuzz::scratch_dir() / "map").string();
  std::map<std::string, std::string> original;
  SmallMap() {
    fuzz::write_small_map(dir);
    for (const auto& f : fuzz::small_map_files()) original[f] = read_file_bytes(dir + "/" + f, f);
  }
};

void read_every_tile(HdMap& map) {
  const double tile_m = fuzz::kSmallResolutionM * fuzz::kSmallTileCells;
  // One query in each tile, and one beyond the map on each side.
  for (int tx = -1; tx <= int(fuzz::kSmallTiles.size()); ++tx) {
    const Eigen::Vector2d centre((tx + 0.5) * tile_m, 0.5 * tile_m);
    map.intensity.cell(centre);
    if (map.points) map.points->points_near(centre, tile_m);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const SmallMap small;
  if (size == 0) return 0;
  const auto& files = fuzz::small_map_files();
  const std::string& replaced = files[data[0] % files.size()];
  const std::string path = small.dir + "/" + replaced;
  fuzz::write_bytes(path, fuzz::as_text(data + 1, size - 1));
  try {
    HdMap map = open_hd_map(small.dir, fuzz::kSmallMapWorld);
    read_every_tile(map);
  } catch (const InputError&) {
  }
  fuzz::write_bytes(path, small.original.at(replaced));
  return 0;
}
