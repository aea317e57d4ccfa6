// lidarloop bench lidar: our scan against bare Embree rtcIntersect1 on the same rays, same scene, same
// process, and against our scan on the same scene built with SSE4.2's kernels (the ISA every x86-64
// has), alternating so all three see the same machine state. Prints one JSON object.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <limits>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "tools/commands.hpp"
#include "tools/scene_setup.hpp"

namespace lidarloop {

using Clock = std::chrono::steady_clock;

static double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// rtcIntersect1 on each ray and nothing else: the floor our scanner is measured against.
static size_t bare_embree(RTCScene scene, const std::vector<LidarRay>& rays, float tnear, float tfar) {
  std::vector<uint8_t> hit(rays.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t i = r.begin(); i != r.end(); ++i) {
      RTCRayHit rh;
      rh.ray.org_x = rays[i].origin.x(), rh.ray.org_y = rays[i].origin.y(), rh.ray.org_z = rays[i].origin.z();
      rh.ray.dir_x = rays[i].direction.x(), rh.ray.dir_y = rays[i].direction.y(), rh.ray.dir_z = rays[i].direction.z();
      rh.ray.tnear = tnear, rh.ray.tfar = tfar, rh.ray.time = 0;
      rh.ray.mask = std::numeric_limits<unsigned>::max(), rh.ray.id = 0, rh.ray.flags = 0;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &context, &rh);
      hit[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  });
  return size_t(std::count(hit.begin(), hit.end(), 1));
}

static int bench_lidar(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  const int scans = int(args.integer("scans", 20, 1, 100000));
  const std::string world = args.text("world", "campus");

  // A drive at 10 m/s along the first road with traffic: a bus parked on the right, a car coming the
  // other way, a truck ahead, a pedestrian on the sidewalk; motion distortion and actor motion on.
  const LoadedWorld probe = load_world(world);
  const Eigen::Isometry3d start = default_start_pose(probe.description, 60.0);
  const double yaw = std::atan2(start.linear()(1, 0), start.linear()(0, 0));
  auto place = [&](ActorType type, double ahead, double left, double heading, double speed) {
    const Eigen::Vector3d p = start * Eigen::Vector3d(ahead, left, 0);
    return straight_actor(type, p.head<2>(), yaw + heading, speed);
  };
  const double lane = probe.description.roads.front().width / 4;
  const std::vector<ActorPlan> actors = {
      place(ActorType::bus, 12, -lane * 0.6, 0, 0), place(ActorType::car, 60, 2 * lane, M_PI, 10),
      place(ActorType::truck, 30, 0, 0, 8), place(ActorType::pedestrian, 20, 3 * lane, M_PI / 2, 1.4)};
  SceneSetup s = make_scene(world, actors, threads);
  const std::string isa = ray_isa();
  // The peer: SSE4.2's kernels, where the pinned ones are others (ray_scene.hpp).
  std::unique_ptr<RayScene> sse;
  if (isa != kRayIsaSse42 && isa != kRayIsaNative) sse = ray_scene(s.world, actors, threads, kRayIsaSse42);
  const Hdl32eConfig config;
  const LidarScanner scanner(config, s.world.materials);
  const PoseAt trajectory = constant_twist(start, 0, 10.0, 0.0);
  const float tnear = float(config.min_range_m) * 0.5f, tfar = float(config.max_range_m) * 1.05f;

  std::vector<double> ours_ms, bare_ms, sse_ms;
  double points = 0;
  for (int i = -2; i < scans; ++i) {  // two warm-up scans
    const int64_t stamp = int64_t(std::max(i, 0)) * config.scan_period_ns();
    auto t0 = Clock::now();
    const PointCloud cloud = scanner.scan(*s.scene, trajectory, stamp, 1, s.actor_poses);
    const double ours = ms_since(t0);
    const std::vector<LidarRay> rays = scanner.rays(trajectory, stamp);
    t0 = Clock::now();
    bare_embree(s.scene->top_level(), rays, tnear, tfar);
    const double bare = ms_since(t0);
    double sse_ours = 0;
    if (sse) {
      t0 = Clock::now();
      scanner.scan(*sse, trajectory, stamp, 1, s.actor_poses);
      sse_ours = ms_since(t0);
    }
    if (i < 0) continue;
    ours_ms.push_back(ours);
    bare_ms.push_back(bare);
    if (sse) sse_ms.push_back(sse_ours);
    points += double(cloud.points.size());
  }
  const double ours = median(ours_ms), bare = median(bare_ms);
  const double realtime = double(config.scan_period_ns()) * 1e-6 / ours;
  nlohmann::json result = {{"bench", "lidar"},
                           {"world", s.world.world.name},
                           {"ray_isa", isa},
                           {"world_triangles", s.scene->world_triangles()},
                           {"actors", actors.size()},
                           {"threads", threads},
                           {"scans", scans},
                           {"rays_per_scan", scanner.rays_per_scan()},
                           {"points_per_scan", points / scans},
                           {"ms_per_scan", ours},
                           {"bare_embree_ms_per_scan", bare},
                           {"ratio", ours / bare},
                           {"rays_per_s", double(scanner.rays_per_scan()) / ours * 1e3},
                           {"realtime_factor", realtime},
                           {"realtime_factor_per_core", realtime / threads}};
  if (sse) {
    result["sse42_ms_per_scan"] = median(sse_ms);
    result["speedup_over_sse42"] = median(sse_ms) / ours;
  }
  std::cout << result.dump(2) << "\n";
  return 0;
}

static int run_bench(const Args& args) {
  const std::string what = args.positional().at(0);
  if (what == "lidar") return bench_lidar(args);
  if (what == "map") return run_bench_map(args);
  if (what == "localizer") return run_bench_localizer(args);
  if (what == "loop") return run_bench_loop(args);
  throw InputError("lidarloop bench: unknown benchmark '" + what + "' (available: lidar, map, localizer, loop)");
}

Command bench_command() {
  return {{"bench",
           "lidarloop bench lidar|map|localizer|loop [--world W] [--threads N] [--scans N] [--cache-tiles N]\n"
           "                [--step M] [--scenario FILE] [--duration S] [--method NAME]",
           "Measure the speed of the ray caster, the map, the localizer or the whole loop, and print it as JSON.\n"
           "lidar: HDL-32E scans against bare Embree rtcIntersect1 on the same rays.\n"
           "map: a localizer's map queries along every road of a built map, and the peak resident set.\n"
           "localizer: a simulated drive replayed into the localizer at 1 and 2 threads; p50/p99 per stage.\n"
           "loop: simulation and localizer in closed loop against the wall clock (real-time factor).",
           {{"world", "NAME|FILE", "world (default campus)"},
            {"threads", "N", "worker threads (default: all cores)"},
            {"scans", "N", "lidar: timed scans after two warm-up scans (default 20)"},
            {"cache-tiles", "N", "map: intensity tiles kept in memory (default 16)"},
            {"step", "M", "map: metres driven between queries (default 12)"},
            {"map", "DIR", "map: a map folder to use instead of the world's cached map"},
            {"scenario", "FILE", "localizer, loop: the drive (default scenarios/campus_traffic.yaml)"},
            {"duration", "S", "localizer, loop: seconds of it (default 20)"},
            {"method", "NAME", "localizer, loop: the method (default: the scenario's)"}},
           1,
           1},
          run_bench};
}

}  // namespace lidarloop
