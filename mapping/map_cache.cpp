#include "mapping/map_cache.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <tbb/parallel_invoke.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"
#include "common/path_beside.hpp"
#include "mapping/file_lock.hpp"
#include "mapping/survey_plot.hpp"
#include "sim/ray_scene.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {

namespace fs = std::filesystem;

constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ULL, kFnvPrime = 0x100000001b3ULL;
// Bump when the mapping drive changes what it produces. 2: the map is a survey (pose error, its own
// HDL-32E unit, curbs moved by the survey error). 3: the survey car rests on the crowned road. 4: lanes
// are driven in parts of 16 scans, each accumulated on its own and merged into the map with Chan's
// formula in a fixed order (place, then lane), where one Welford stream ran lane after lane: the same
// points per cell, means and variances that may differ in the last bit of the stored float (large: 44
// of its cells' m2 by one ulp; campus: none). 5: the point-cloud layer (points.yaml, points/) for the
// gicp method. 6: the survey's scans are the points a driver decodes from the HDL-32E's packets (block
// azimuth on the 0.01 deg grid, 2 mm ranges, the calibration's elevations). 7: Embree's kernels fixed
// to SSE4.2 (sim/ray_scene.cpp), so a map built on one machine is the map built on any other. 8: a
// Lanelet2 world's lanes are surveyed along the line a car drives (sim/lane_graph.hpp's
// route_driven_line), not their kinked centrelines. 9: the survey's oncoming traffic (`traffic`) stands
// on the ground, where it stood at height 0.
constexpr int kMapFormatVersion = 9;

static void hash_bytes(uint64_t& h, const std::string& bytes) {
  for (unsigned char c : bytes) h = (h ^ c) * kFnvPrime;
}

static void hash_file(uint64_t& h, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read file");
  std::stringstream s;
  s << in.rdbuf();
  hash_bytes(h, path.substr(path.find_last_of('/') + 1));
  hash_bytes(h, s.str());
}

// The Lanelet2 or OpenDRIVE map a world is made from, and the projector file beside it if there is one:
// a world.yaml naming a map (`lanelet2: {file}`, `opendrive: {file}`), or the map itself.
static std::vector<std::string> lanelet2_files(const std::string& world_path) {
  std::string map;
  if (fs::path(world_path).extension() == ".osm" || fs::path(world_path).extension() == ".xodr") {
    map = world_path;
  } else {
    YAML::Node root;
    try {
      root = YAML::LoadFile(world_path);
    } catch (const YAML::Exception&) {
      return {};  // loading the world reports what is wrong with its file
    }
    const char* key = root.IsMap() && root["opendrive"] ? "opendrive" : "lanelet2";
    if (!root.IsMap() || !root[key] || !root[key]["file"]) return {};
    map = path_beside(world_path, root[key]["file"].as<std::string>());
  }
  std::vector<std::string> files;
  if (map != world_path) files.push_back(map);
  const std::string projector = (fs::path(map).parent_path() / "map_projector_info.yaml").string();
  if (fs::is_regular_file(projector)) files.push_back(projector);
  return files;
}

std::string map_cache_root() {
  if (const char* env = std::getenv("LIDARLOOP_MAP_CACHE"); env && *env) return env;
  return std::string(LIDARLOOP_BUILD_DIR) + "/maps";
}

std::string map_hash(const std::string& world_name, const MappingOptions& options) {
  const std::string world_path = world_file(world_name);
  uint64_t h = kFnvOffset;
  hash_file(h, world_path);
  for (const std::string& file : lanelet2_files(world_path)) hash_file(h, file);
  hash_file(h, data_dir() + "/assets/materials.yaml");
  std::vector<std::string> actors;
  for (const auto& entry : fs::directory_iterator(actors_dir()))
    if (entry.path().extension() == ".obj") actors.push_back(entry.path().string());
  std::sort(actors.begin(), actors.end());
  for (const auto& a : actors) hash_file(h, a);
  // The survey's scans are cast with the pinned kernels (ray_isa): another set makes another map.
  hash_bytes(h, options.describe() + " format=" + std::to_string(kMapFormatVersion) + " rays=" + ray_isa());
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

namespace {

// Temporary folders of a build sit next to the final place (same file system, so the rename is atomic)
// and are named after it, so that a later build of the same map can find those a crashed one left.
constexpr const char* kBuildTempInfix = ".build-";
constexpr const char* kLegacyPartialSuffix = ".partial";  // before builds were locked: one shared folder

bool cached_map_matches(const MapLocation& loc) {
  if (!fs::exists(loc.dir + "/map.yaml")) return false;
  return read_intensity_map_header(loc.dir).world_hash == loc.hash;
}

// Temporary folders of earlier builds of this map. Only a holder of the map's lock builds into one,
// so while we hold it, any that exist belong to builds that died.
void remove_stale_builds(const std::string& final_dir) {
  const fs::path final_path(final_dir);
  const std::string prefix = final_path.filename().string() + kBuildTempInfix;
  std::vector<fs::path> stale;
  std::error_code ec;
  for (fs::directory_iterator it(final_path.parent_path(), ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().starts_with(prefix)) stale.push_back(it->path());
  stale.push_back(final_dir + kLegacyPartialSuffix);
  for (const fs::path& p : stale) fs::remove_all(p, ec);  // best effort: a leftover is ignored, never read
}

// A fresh, uniquely named folder next to `final_dir` (mkdtemp: no two builders ever share one).
std::string make_build_dir(const std::string& final_dir) {
  std::string name = final_dir + kBuildTempInfix + "XXXXXX";
  if (::mkdtemp(name.data()) == nullptr)
    throw InputError(name + ": cannot create a temporary map folder: " + std::strerror(errno));
  // mkdtemp makes it private (0700); once renamed it is the map, which others sharing the cache read.
  std::error_code ec;
  fs::permissions(name,
                  fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                      fs::perms::others_exec,
                  ec);
  return name;
}

// Puts the finished map `built` at `final_dir` in one step, so a reader finds the old map or the new
// one, never a mixture or a half. A first build is a rename; a rebuild (--force, or a map of a stale
// format in its place) swaps the two folders with renameat2(RENAME_EXCHANGE) and deletes the old one.
// File systems without the exchange (NFS) fall back to two renames, between which the map is briefly
// absent: a reader then finds no map, waits on the lock and finds the new one.
void move_into_place(const std::string& built, const std::string& final_dir) {
  if (::rename(built.c_str(), final_dir.c_str()) == 0) return;
  if (errno != EEXIST && errno != ENOTEMPTY)
    throw InputError(final_dir + ": cannot move the built map into place: " + std::strerror(errno));
  if (::renameat2(AT_FDCWD, built.c_str(), AT_FDCWD, final_dir.c_str(), RENAME_EXCHANGE) != 0) {
    if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
      throw InputError(final_dir + ": cannot swap in the rebuilt map: " + std::strerror(errno));
    const std::string old = make_build_dir(final_dir);
    fs::remove(old);  // rename replaces only an empty folder or none
    if (::rename(final_dir.c_str(), old.c_str()) != 0 || ::rename(built.c_str(), final_dir.c_str()) != 0)
      throw InputError(final_dir + ": cannot replace the map: " + std::strerror(errno));
    fs::remove_all(old);
    return;
  }
  fs::remove_all(built);  // the old map, swapped out
}

}  // namespace

MapLocation ensure_map(const std::string& world_name, const MappingOptions& options, bool force) {
  const std::string world_path = world_file(world_name);
  MapLocation loc;
  loc.hash = map_hash(world_name, options);
  // The world is named by its description; it is built only when its map must be.
  const std::string name = load_world_description_of(world_path).name;
  const std::string root = map_cache_root();
  loc.dir = root + "/" + name + "-" + loc.hash;
  // A map in its place is always whole (see move_into_place): reading it needs no lock.
  if (!force && cached_map_matches(loc)) return loc;

  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) throw InputError(root + ": cannot create the map cache folder: " + ec.message());
  const bool terminal = isatty(STDOUT_FILENO);
  // One builder per map at a time, across processes; the others wait here, then find its map.
  const FileLock lock(loc.dir + ".lock", [&] {
    if (!terminal) return;
    std::printf("waiting for another process's build of the %s map (%s.lock)\n", name.c_str(), loc.dir.c_str());
    std::fflush(stdout);
  });
  if (!force && cached_map_matches(loc)) return loc;
  remove_stale_builds(loc.dir);
  const LoadedWorld w = load_mapped_world(world_path, options);

  const auto t0 = std::chrono::steady_clock::now();
  const std::string tmp = make_build_dir(loc.dir);
  // Tiles are written as the drive finishes them: memory holds the open ones, not the map.
  IntensityMapWriter writer(tmp);
  PointMapWriter points(tmp);
  const IntensityMapHeader header = run_mapping_drive(
      w.description, w.world, w.materials, actors_dir(), options, loc.hash,
      [&](const IntensityMapHeader& h, const std::pair<int, int>& key, std::vector<IntensityMoments>& cells) {
        writer.write_tile(h, key, cells);
      },
      [&](double f) {
        if (!terminal) return;
        std::printf("\rmapping %s %3d%%", w.world.name.c_str(), int(f * 100));
        std::fflush(stdout);
      },
      &points);
  if (terminal) std::printf("\r%40s\r", "");
  writer.finish(header);
  // The curbs and the pictures are independent files: made side by side.
  tbb::parallel_invoke(
      [&] {
        const SurveyDrive survey = mapping_survey(w.description, options);
        write_curb_map(tmp + "/curbs.geojson", surveyed_curbs(w.world, survey, options));
        write_survey_error_png(tmp + "/survey_error.png", w.world, survey);
      },
      [&] { write_intensity_pngs(tmp, tmp + "/mean.png", tmp + "/variance.png"); });
  move_into_place(tmp, loc.dir);
  loc.built = true;
  loc.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return loc;
}

void write_intensity_pngs(const std::string& map_dir, const std::string& mean_png, const std::string& variance_png,
                          int max_pixels) {
  const IntensityMapHeader h = read_intensity_map_header(map_dir);
  if (h.tiles.empty()) throw InputError(map_dir + ": the map has no tiles");
  int tx0 = INT32_MAX, ty0 = INT32_MAX, tx1 = INT32_MIN, ty1 = INT32_MIN;
  for (const auto& [tx, ty] : h.tiles)
    tx0 = std::min(tx0, tx), ty0 = std::min(ty0, ty), tx1 = std::max(tx1, tx), ty1 = std::max(ty1, ty);
  // The picture is drawn row by row across the whole map: with a tile of every column cached, each tile
  // is read once (with fewer, every pixel row read them all again: a third of building campus's map).
  IntensityMap map(map_dir, size_t(tx1 - tx0 + 1));
  const int cells_x = (tx1 - tx0 + 1) * h.tile_cells, cells_y = (ty1 - ty0 + 1) * h.tile_cells;
  const int step = std::max(1, (std::max(cells_x, cells_y) + max_pixels - 1) / max_pixels);
  const int w = cells_x / step, hgt = cells_y / step;
  cv::Mat mean(hgt, w, CV_8UC1, cv::Scalar(0)), var(hgt, w, CV_8UC1, cv::Scalar(0)),
      seen(hgt, w, CV_8UC1, cv::Scalar(0));
  constexpr double kMeanScale = 255.0 / 60.0, kVarianceScale = 255.0 / 200.0;  // intensity counts, counts^2
  for (int py = 0; py < hgt; ++py)
    for (int px = 0; px < w; ++px) {
      const Eigen::Vector2d xy((tx0 * h.tile_cells + px * step + 0.5) * h.resolution_m,
                               (ty0 * h.tile_cells + (hgt - 1 - py) * step + 0.5) * h.resolution_m);
      if (const auto c = map.cell(xy)) {
        mean.at<uint8_t>(py, px) = uint8_t(std::min(255.0, c->mean * kMeanScale));
        var.at<uint8_t>(py, px) = uint8_t(std::min(255.0, c->variance() * kVarianceScale));
        seen.at<uint8_t>(py, px) = 255;
      }
    }
  cv::Mat coloured;
  cv::applyColorMap(var, coloured, cv::COLORMAP_TURBO);
  coloured.setTo(cv::Scalar(0, 0, 0), seen == 0);
  if (!cv::imwrite(mean_png, mean)) throw InputError(mean_png + ": cannot write PNG");
  if (!cv::imwrite(variance_png, coloured)) throw InputError(variance_png + ": cannot write PNG");
}

}  // namespace lidarloop
