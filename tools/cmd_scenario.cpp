// lidarloop validate / simulate: check a scenario, or run it without a localizer and write its streams.
#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "loop/localizer_setup.hpp"
#include "loop/run_recording.hpp"
#include "tools/commands.hpp"
#include "tools/csv_streams.hpp"
#include "tools/scene_setup.hpp"
#include "tools/world_map_png.hpp"

namespace lidarloop {

namespace {

int run_validate(const Args& args) {
  for (const auto& file : args.positional()) {
    const LoadedScenario s = load_scenario_and_world(file);
    std::cout << file << ": ok (world " << s.world.world.name << ", " << s.scenario.duration_s << " s, route "
              << int(s.resolved.ego_route.length) << " m, " << s.resolved.actors.size() << " traffic actors)\n";
  }
  return 0;
}

int run_simulate(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  LoadedScenario s = load_scenario_and_world(args.positional().at(0));
  if (auto seed = args.value("seed")) s.scenario.seed = uint64_t(args.integer("seed", 0, 0, 1L << 62));
  if (args.value("duration")) s.scenario.duration_s = args.number("duration", s.scenario.duration_s);
  if (s.scenario.duration_s <= 0) throw InputError("--duration must be positive");
  const std::string out = args.text("out", "out/" + std::filesystem::path(s.scenario.file).stem().string());
  const int scan_every = int(args.integer("scan-every", s.scenario.scan_every, 0, 1000000));

  // The outputs first: one that cannot be written fails before the simulation is built.
  CsvStreams streams(out, LocalFrame(s.world.description.origin), scan_every);
  const std::unique_ptr<RecordingSink> recorder =
      start_recording(args.value("record"), s.scenario, "", scan_recording_option(args));
  Simulation sim(s.scenario, s.world.description, s.world.world, s.world.materials, actors_dir(), threads);
  TeeSink sink(streams, recorder.get());
  const bool terminal = isatty(STDOUT_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  sim.run(sink, [&](double fraction) {
    if (!terminal) return;
    std::printf("\rsimulate %3d%%  %.1f of %.1f s", int(fraction * 100), fraction * s.scenario.duration_s,
                s.scenario.duration_s);
    std::fflush(stdout);
  });
  if (recorder) recorder->log().close();
  streams.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (terminal) std::printf("\r%60s\r", "");

  std::vector<MapOverlay> overlays;
  for (const auto& [name, path] : streams.actor_paths()) overlays.push_back({path, {255, 120, 0}, 2});
  overlays.push_back({streams.ego_path(), {0, 0, 255}, 3});
  write_world_map_png(out + "/topview.png", s.world.world, s.world.materials, 0.25, overlays);

  std::cout << "scenario     " << s.scenario.file << " (seed " << s.scenario.seed << ")\n"
            << "simulated    " << s.scenario.duration_s << " s in " << wall << " s wall ("
            << s.scenario.duration_s / wall << "x real time, " << threads << " thread(s))\n"
            << "scans        " << streams.scans() << "\n"
            << "cross-track  " << streams.cross_track_rms() << " m RMS (controller on ground truth)\n"
            << "output       " << out << "/ (truth, can, gps, rtk, actors .csv; scans/*.ply; topview.png)\n";
  return 0;
}

}  // namespace

Command validate_command() {
  return {{"validate",
           "lidarloop validate SCENARIO.yaml [SCENARIO.yaml ...]",
           "Check scenarios without running them: syntax, keys, values, and paths on the world's roads.",
           {},
           1,
           1000},
          run_validate};
}

Command simulate_command() {
  return {{"simulate",
           "lidarloop simulate SCENARIO.yaml [--out DIR] [--seed N] [--duration S] [--scan-every N]\n"
           "                         [--record FILE.mcap [--packets|--packets-only]]",
           "Run a scenario's world, ego, traffic and sensors without a localizer; write the streams as CSV,\n"
           "every Nth scan as PLY, and a top view of roads, actors and the ego's path.",
           {{"out", "DIR", "output folder (default out/<scenario name>)"},
            {"seed", "N", "override the scenario's seed"},
            {"duration", "S", "override the scenario's duration, seconds"},
            {"scan-every", "N", "write every Nth scan as PLY (0: none; default from the scenario, 10)"},
            {"record", "FILE.mcap", "also record every stream as an MCAP log"},
            {"packets", "", "with --record: also log the HDL-32E's raw UDP packets on /velodyne_packets"},
            {"packets-only", "",
             "with --record: log the scans only as the HDL-32E's packets (the sensor's own data rate; "
             "replay and export decode them)"},
            {"threads", "N", "worker threads (default: all cores)"}},
           1,
           1},
          run_simulate};
}

}  // namespace lidarloop
