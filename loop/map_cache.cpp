#include "loop/map_cache.hpp"

#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"
#include "loop/survey_plot.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {

namespace fs = std::filesystem;

constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ULL, kFnvPrime = 0x100000001b3ULL;
// Bump when the mapping drive changes what it produces. 2: the map is a survey (pose error, its own
// HDL-32E unit, curbs moved by the survey error). 3: the survey car rests on the crowned road.
constexpr int kMapFormatVersion = 3;

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

std::string map_cache_root() {
  if (const char* env = std::getenv("LIDARLOOP_MAP_CACHE"); env && *env) return env;
  return std::string(LIDARLOOP_BUILD_DIR) + "/maps";
}

std::string map_hash(const std::string& world_name, const MappingOptions& options) {
  const std::string world_path = world_file(world_name);
  uint64_t h = kFnvOffset;
  hash_file(h, world_path);
  hash_file(h, data_dir() + "/assets/materials.yaml");
  std::vector<std::string> actors;
  for (const auto& entry : fs::directory_iterator(actors_dir()))
    if (entry.path().extension() == ".obj") actors.push_back(entry.path().string());
  std::sort(actors.begin(), actors.end());
  for (const auto& a : actors) hash_file(h, a);
  hash_bytes(h, options.describe() + " format=" + std::to_string(kMapFormatVersion));
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

MapLocation ensure_map(const std::string& world_name, const MappingOptions& options, bool force) {
  const std::string world_path = world_file(world_name);
  MapLocation loc;
  loc.hash = map_hash(world_name, options);
  const LoadedWorld w = load_mapped_world(world_path, options);
  loc.dir = map_cache_root() + "/" + w.world.name + "-" + loc.hash;
  if (!force && fs::exists(loc.dir + "/map.yaml")) {
    const IntensityMapHeader header = read_intensity_map_header(loc.dir);
    if (header.world_hash == loc.hash) return loc;
  }

  const auto t0 = std::chrono::steady_clock::now();
  const bool terminal = isatty(STDOUT_FILENO);
  IntensityMapBuilder builder =
      run_mapping_drive(w.description, w.world, w.materials, actors_dir(), options, loc.hash, [&](double f) {
        if (!terminal) return;
        std::printf("\rmapping %s %3d%%", w.world.name.c_str(), int(f * 100));
        std::fflush(stdout);
      });
  if (terminal) std::printf("\r%40s\r", "");
  // Build next to the final place and rename, so a half-written map is never found in the cache.
  const std::string tmp = loc.dir + ".partial";
  fs::remove_all(tmp);
  builder.save(tmp);
  const SurveyDrive survey = mapping_survey(w.description, options);
  write_curb_map(tmp + "/curbs.geojson", surveyed_curbs(w.world, survey, options));
  write_intensity_pngs(tmp, tmp + "/mean.png", tmp + "/variance.png");
  write_survey_error_png(tmp + "/survey_error.png", w.world, survey);
  fs::remove_all(loc.dir);
  fs::rename(tmp, loc.dir);
  loc.built = true;
  loc.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return loc;
}

void write_intensity_pngs(const std::string& map_dir, const std::string& mean_png, const std::string& variance_png,
                          int max_pixels) {
  IntensityMap map(map_dir, 8);
  const IntensityMapHeader& h = map.header();
  if (h.tiles.empty()) throw InputError(map_dir + ": the map has no tiles");
  int tx0 = INT32_MAX, ty0 = INT32_MAX, tx1 = INT32_MIN, ty1 = INT32_MIN;
  for (const auto& [tx, ty] : h.tiles)
    tx0 = std::min(tx0, tx), ty0 = std::min(ty0, ty), tx1 = std::max(tx1, tx), ty1 = std::max(ty1, ty);
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
