// lidarloop scan: one HDL-32E scan of a world, as PLY and a bird's-eye PNG.
#include <chrono>
#include <climits>
#include <iostream>
#include <thread>

#include "common/units.hpp"
#include "scoring/birdseye.hpp"
#include "tools/commands.hpp"
#include "tools/ply_file.hpp"
#include "tools/scene_setup.hpp"

namespace lidarloop {

int thread_count(const Args& args) {
  const long n = args.integer("threads", 0, 0, 1024);
  return n > 0 ? int(n) : int(std::max(1u, std::thread::hardware_concurrency()));
}

std::optional<Realism> realism_option(const Args& args) {
  const auto word = args.value("realism");
  if (!word) return std::nullopt;
  const std::optional<Realism> realism = parse_realism(*word);
  if (!realism) throw InputError("--realism must be ideal, typical or harsh, got '" + *word + "'");
  return realism;
}

static int run_scan(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  Hdl32eConfig config;
  if (const auto file = args.value("lidar")) {
    const YamlReader yaml = YamlReader::open(*file);
    read_hdl32e_config(yaml, yaml.root(), config);
  }
  if (args.flag("no-motion-distortion")) config.motion_distortion = false;
  std::vector<ActorPlan> actors;
  for (const auto& spec : args.values("actor")) actors.push_back(parse_actor(spec));
  const auto seed = uint64_t(args.integer("seed", 1, 0, LONG_MAX));
  const double speed = args.number("speed", 0.0), yaw_rate = args.number("yaw-rate", 0.0) * kDeg;
  const std::string png = args.text("png", "");
  if (!png.empty() && png.size() < 4) throw InputError("--png: '" + png + "' must end in .png");
  if (!png.empty() && png.substr(png.size() - 4) != ".png") throw InputError("--png: '" + png + "' must end in .png");

  const SceneSetup s = make_scene(args.text("world", "campus"), actors, threads);
  Eigen::Isometry3d start = default_start_pose(s.world.description);
  if (args.value("pose")) {
    const auto p = args.numbers("pose", 3);
    if (!s.world.world.bounds.contains(Eigen::Vector2d(p[0], p[1])))
      throw InputError("--pose: (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ") is outside world '" +
                       s.world.world.name + "'");
    start = to_isometry({p[0], p[1], p[2] * kDeg});
  }
  const PoseAt trajectory = constant_twist(start, 0, speed, yaw_rate);
  const LidarScanner scanner(config, s.world.materials);

  const auto t0 = std::chrono::steady_clock::now();
  const PointCloud cloud = scanner.scan(*s.scene, trajectory, 0, seed, s.actor_poses);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  std::cout << "scan         " << cloud.points.size() << " points from " << scanner.rays_per_scan() << " firings ("
            << config.cycles_per_scan() << " cycles at " << config.rotation_hz << " Hz) in " << ms << " ms on "
            << threads << " thread(s)\n";
  if (const auto out = args.value("out")) {
    write_ply(*out, cloud);
    std::cout << "point cloud  " << *out << "\n";
  }
  if (!png.empty()) {
    BirdseyeOptions view;
    view.half_extent_m = args.number("png-range", view.half_extent_m);
    if (view.half_extent_m < 5 || view.half_extent_m > 200) throw InputError("--png-range must be 5 to 200 m");
    write_birdseye_png(png, cloud, trajectory(0) * config.mount(), s.world.world.curbs, view);
    std::cout << "picture      " << png << "\n";
  }
  return 0;
}

Command scan_command() {
  return {{"scan",
           "lidarloop scan [--world W] [--pose X,Y,YAW_DEG] [--speed V] [--yaw-rate DEG_S] [--out scan.ply] "
           "[--png scan.png]",
           "Simulate one HDL-32E scan at a pose (moving at constant speed and yaw rate) and write it.",
           {{"world", "NAME|FILE", "world name under maps/ or a world.yaml path (default campus)"},
            {"pose", "X,Y,YAW_DEG", "vehicle pose at the scan's start, local metres and degrees"},
            {"speed", "M_S", "vehicle speed during the scan (default 0)"},
            {"yaw-rate", "DEG_S", "vehicle yaw rate during the scan (default 0)"},
            {"actor", "TYPE,X,Y,YAW_DEG[,SPEED]", "add a car|bus|truck|pedestrian|cyclist (repeatable)"},
            {"lidar", "FILE.yaml", "HDL-32E parameter overrides"},
            {"no-motion-distortion", "", "cast every firing from the scan's starting pose"},
            {"seed", "N", "noise seed (default 1)"},
            {"threads", "N", "worker threads (default: all cores)"},
            {"out", "FILE.ply", "write the point cloud (sensor frame)"},
            {"png", "FILE.png", "write a bird's-eye picture with the curb map"},
            {"png-range", "M", "the picture covers +-M metres around the sensor (default 50)"}},
           0,
           0},
          run_scan};
}

}  // namespace lidarloop
