#pragma once
// Where built maps live: a cache folder per world and mapping options, keyed by a hash of everything
// the map is made from, so an unchanged map is never rebuilt. Under the build folder unless
// $LIDARLOOP_MAP_CACHE says otherwise; never committed.
#include <string>

#include "mapping/mapping_drive.hpp"

namespace lidarloop {

std::string map_cache_root();

struct MapLocation {
  std::string dir;  // <root>/<world>-<hash>
  std::string hash;
  bool built = false;  // built now (false: found in the cache)
  double build_s = 0;
};

// The cache key of a world's map: a hash of the world file, the materials, the actor meshes, the
// mapping options and the map format version.
std::string map_hash(const std::string& world, const MappingOptions& options);

// Finds the map of `world` (name or world.yaml path) made with `options`, or builds it (or rebuilds
// it with `force`). Shows progress on a terminal.
//
// Safe when many processes share the cache (one machine, or a shared volume: see mapping/file_lock.hpp
// for what NFS needs): a build holds the lock file <root>/<world>-<hash>.lock, looks in the cache again
// once it has the lock (a process that waited finds the map the first one built and does not rebuild),
// builds into a folder of its own next to the final place and renames it into place, so no one ever
// reads half a map. Temporary folders that a crashed build left are removed by the next build.
MapLocation ensure_map(const std::string& world, const MappingOptions& options, bool force);

// A bird's-eye PNG of the intensity layer's mean (grey) and variance (colour), downsampled so the
// longer side is at most max_pixels.
void write_intensity_pngs(const std::string& map_dir, const std::string& mean_png, const std::string& variance_png,
                          int max_pixels = 3000);

}  // namespace lidarloop
