// lidarloop map: build (or find) a world's HD map; the `bench map` memory benchmark lives here too.
#include <sys/resource.h>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include <filesystem>

#include "common/output_dir.hpp"
#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "localizer/hd_map.hpp"
#include "loop/run_outputs.hpp"
#include "mapping/autoware_export.hpp"
#include "mapping/map_cache.hpp"
#include "sim/path.hpp"
#include "sim/world_assets.hpp"
#include "tools/commands.hpp"
#include "tools/scene_setup.hpp"

namespace lidarloop {

namespace {

MappingOptions mapping_options(const Args& args) {
  MappingOptions o = mapping_options_for(realism_option(args).value_or(Realism::typical));
  o.traffic = args.flag("traffic");
  o.resolution = args.number("resolution", o.resolution);
  if (o.resolution < 0.05 || o.resolution > 2.0) throw InputError("--resolution must be 0.05 to 2 m");
  o.speed = args.number("speed", o.speed);
  if (o.speed < 1 || o.speed > 40) throw InputError("--speed must be 1 to 40 m/s");
  if (const auto file = args.value("survey")) {
    const YamlReader yaml = YamlReader::open(*file);
    read_survey_options(yaml, yaml.root(), o);
  }
  return o;
}

// The survey's error and what it does to the curbs, recomputed from the options (cheap: no LiDAR), so
// the figures are printed whether the map was built now or found in the cache.
void print_survey(const std::string& world, const MappingOptions& o, const std::string& map_dir) {
  constexpr double kCm = 100.0;
  const LoadedWorld w = load_mapped_world(world, o);
  const SurveyDrive survey = mapping_survey(w.description, o);
  double east2 = 0, north2 = 0, heading2 = 0, max_position = 0, max_heading = 0;
  for (const Pose2d& e : survey.error.samples) {
    east2 += e.x * e.x, north2 += e.y * e.y, heading2 += e.yaw * e.yaw;
    max_position = std::max(max_position, std::hypot(e.x, e.y));
    max_heading = std::max(max_heading, std::abs(e.yaw));
  }
  const double n = double(std::max<size_t>(1, survey.error.samples.size()));
  const CurbMap world_curbs = densify_curb_map(w.world.curb_map(), o.survey_error.sample_spacing_m);
  // The map's curbs as the map holds them: drawn to its labelling convention, then moved by the survey.
  const CurbShiftStats c = curb_shift_stats(world_curbs, surveyed_curbs(w.world, survey, o));
  auto fixed = [](double v, int digits) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v;
    return s.str();
  };
  std::cout << "survey       " << fixed(survey.length_m / 1000, 2) << " km of lanes, HDL-32E unit "
            << o.survey_unit_serial << "; position error RMS east " << fixed(std::sqrt(east2 / n) * kCm, 2)
            << " cm, north " << fixed(std::sqrt(north2 / n) * kCm, 2) << " cm, max " << fixed(max_position * kCm, 2)
            << " cm; heading RMS " << fixed(std::sqrt(heading2 / n) * kDegPerRad, 3) << " deg, max "
            << fixed(max_heading * kDegPerRad, 3) << " deg\n"
            << "curb shift   across the curb line: mean " << fixed(c.across_mean_m * kCm, 2) << " cm, sigma "
            << fixed(c.across_sigma_m * kCm, 2) << " cm, max " << fixed(c.across_max_abs_m * kCm, 2)
            << " cm; whole shift mean " << fixed(c.shift_mean_m * kCm, 2) << " cm, max "
            << fixed(c.shift_max_m * kCm, 2) << " cm (" << c.points << " curb points)\n"
            << "survey plot  " << map_dir << "/survey_error.png\n";
}

// `--export FORMAT DIR`: the formats other programs load a map in. Checked before the map is built, so
// a mistake costs no mapping drive.
std::optional<std::string> export_dir(const Args& args) {
  const auto format = args.value("export");
  const bool has_dir = args.positional().size() > 1;
  if (!format && has_dir) throw InputError("a second argument (a folder) goes with --export FORMAT");
  if (!format) return std::nullopt;
  if (*format != "autoware") throw InputError("--export: unknown format '" + *format + "' (known: autoware)");
  if (!has_dir)
    throw InputError("--export " + *format + " needs a folder: lidarloop map WORLD --export " + *format + " DIR");
  prepare_output_dir(args.positional().at(1));
  return args.positional().at(1);
}

void print_export(const AutowareExportSummary& e) {
  const Lanelet2Summary& l = e.lanelet2;
  std::cout << "autoware     " << e.dir << "/{" << kAutowarePointCloudFile << ", " << kAutowareLanelet2File << ", "
            << kAutowareProjectorFile << "}\n"
            << "  points     " << e.points << "\n"
            << "  lanelet2   road lanelets " << l.road_lanelets << " (" << l.intersection_lanelets << " in "
            << l.junctions << " junctions, " << l.turn_lanelets << " joining roads), curbstones " << l.curbstones
            << ", crosswalks " << l.crosswalks << ", stop lines " << l.stop_lines << " + " << l.derived_stop_lines
            << " derived before crosswalks, nodes " << l.nodes << "\n";
  if (l.short_lanelets)
    std::cout << "  warning    " << l.short_lanelets
              << " lanelets shorter than 3 m between junctions too close together\n";
}

int run_map(const Args& args) {
  const auto limit = limit_threads(thread_count(args));
  const MappingOptions options = mapping_options(args);
  const std::optional<std::string> out = export_dir(args);
  const MapLocation loc = ensure_map(args.positional().at(0), options, args.flag("force"));
  const IntensityMapHeader h = read_intensity_map_header(loc.dir);
  std::cout << "map          " << loc.dir << (loc.built ? " (built)" : " (found in the cache)") << "\n";
  if (loc.built) std::cout << "built in     " << loc.build_s << " s\n";
  std::cout << "world        " << h.world << " (hash " << h.world_hash << ")\n"
            << "intensity    " << h.tiles.size() << " tiles of " << h.tile_size_m() << " m, " << h.resolution_m
            << " m cells; mean.png, variance.png\n"
            << "curbs        " << loc.dir << "/curbs.geojson\n";
  print_survey(args.positional().at(0), options, loc.dir);
  if (out) {
    AutowareExportConfig config;
    config.voxel_m = args.number("export-voxel", config.voxel_m);
    print_export(export_autoware_map(args.positional().at(0), options, loc.dir, *out, config));
  }
  return 0;
}

// What a localizer asks of the map while driving: at every step the curbs around the car and the
// intensity cells of its 40 m x 40 m grid S. Reports the process's own peak resident set.
int bench_map(const Args& args) {
  const std::string world = args.text("world", "campus");
  const LoadedWorld w = load_world(world);
  // The map given, or the cached one (which must exist: building it here would measure the builder).
  std::string dir = args.text("map", "");
  if (dir.empty()) {
    dir = map_cache_root() + "/" + w.world.name + "-" + map_hash(world, MappingOptions{});
    if (!std::filesystem::exists(dir + "/map.yaml"))
      throw InputError("no map of '" + w.world.name + "' in the cache: build it first with `lidarloop map " + world +
                       "`, or give --map DIR");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const size_t cache_tiles = size_t(args.integer("cache-tiles", 16, 1, 100000));
  HdMap hd = open_hd_map(dir, w.world.name, cache_tiles);
  const CurbLayer& curbs = hd.curbs;
  IntensityMap& map = hd.intensity;
  const double step = args.number("step", 12.0);  // m between queries: 1 s at 12 m/s
  constexpr double kGridHalf = 20.0;              // grid S: 200 x 200 cells of 0.2 m
  size_t windows = 0, cells = 0, curb_points = 0;
  for (const auto& road : w.description.roads) {
    const Path path = lane_path(road, Lane::right, false);
    for (double s = 0; s < path.length; s += step, ++windows) {
      const Pose2d p = path.pose_at(s);
      curb_points += curbs.window({p.x, p.y}, kGridHalf).size();
      for (double dy = -kGridHalf; dy < kGridHalf; dy += map.header().resolution_m)
        for (double dx = -kGridHalf; dx < kGridHalf; dx += map.header().resolution_m)
          if (map.cell({p.x + dx, p.y + dy})) ++cells;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const nlohmann::json result = {{"bench", "map"},
                                 {"world", w.world.name},
                                 {"map", dir},
                                 {"tiles_in_map", map.header().tiles.size()},
                                 {"cache_tiles", cache_tiles},
                                 {"windows", windows},
                                 {"cells_with_data", cells},
                                 {"curb_points_returned", curb_points},
                                 {"tiles_loaded", map.tiles_loaded()},
                                 {"ms_per_window", seconds * 1e3 / double(std::max<size_t>(windows, 1))},
                                 {"peak_rss_mb", double(usage.ru_maxrss) / 1024.0}};
  std::cout << result.dump(2) << "\n";
  return 0;
}

}  // namespace

Command map_command() {
  return {{"map",
           "lidarloop map WORLD [--traffic] [--force] [--resolution M] [--speed V] [--realism PROFILE]\n"
           "                    [--survey FILE.yaml] [--export autoware DIR]",
           "Build a world's HD map by a mapping drive over every lane (or find it in the cache): the curb\n"
           "layer (GeoJSON) and the intensity layer (tiles of per-cell count, mean and variance: equation 8).\n"
           "The map is a survey: scans placed with an RTK-INS pose error, by another HDL-32E unit, and the\n"
           "curbs moved by that error; prints the error and writes survey_error.png beside the map.\n"
           "--export autoware DIR writes the map as Autoware loads it: pointcloud_map.pcd, lanelet2_map.osm\n"
           "(Lanelet2) and map_projector_info.yaml.",
           {{"traffic", "", "oncoming traffic during the drive (raises the variance of the cells it crosses)"},
            {"force", "", "rebuild even if the cache has this map"},
            {"resolution", "M", "intensity cell size (default 0.2 m)"},
            {"speed", "M_S", "mapping drive speed (default 15 m/s)"},
            {"realism", "PROFILE", "the survey of a realism profile: ideal, typical (default) or harsh"},
            {"survey", "FILE", "survey settings in YAML (unit_serial, sigma_xy_m, heading_sigma_deg, ...)"},
            {"threads", "N", "worker threads (default: all cores)"},
            {"export", "FORMAT", "also write the map for another program into the folder given after it: autoware"},
            {"export-voxel", "M", "voxel of the exported point cloud (default 0.4 m, the point layer's; not finer)"}},
           1,
           2},
          run_map};
}

int run_bench_map(const Args& args) { return bench_map(args); }

}  // namespace lidarloop
