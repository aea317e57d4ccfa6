// lidarloop replay: a recorded run's streams, read back from its MCAP log, fed to the localizer in
// the order they were recorded, and scored against the recorded ground truth. The scenario, seed and
// method come from the log itself, so the estimates are those of the live run, bit for bit. Replay
// does not simulate: the curb the traffic hid (metrics.json's curb_hidden_fraction) is read from the
// log's /truth/curb_visibility, as the live run measured it (null for a log without it). The vehicle
// is the log's too (assets/vehicle.yaml may have changed since); the world and its map are found by
// name, with a note on stderr when the map is not the one the run had.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "common/input_error.hpp"
#include "common/output_dir.hpp"
#include "logs/localizer_status.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/scan_messages.hpp"
#include "logs/tum_file.hpp"
#include "loop/localizer_backend.hpp"
#include "loop/localizer_setup.hpp"
#include "loop/recorded_log.hpp"
#include "loop/run_outputs.hpp"
#include "loop/run_recording.hpp"
#include "mapping/map_cache.hpp"
#include "scoring/result_files.hpp"
#include "sim/ray_scene.hpp"
#include "tools/commands.hpp"

namespace lidarloop {
namespace {

namespace topics = log_topics;

// Replay with the recorded method must give the live run's estimates bit for bit; the log's
// /localizer/status (every scan's health, lost state and protection bounds) says what they were.
// A note names the first scan whose status differs, or a count that does; nothing to compare in a log
// without statuses (recorded by `simulate` or an older lidarloop).
void compare_statuses(const std::string& log, const std::vector<ros2::Bytes>& recorded,
                      const std::vector<LocalizerEstimate>& estimates) {
  if (recorded.empty()) return;
  if (recorded.size() != estimates.size()) {
    std::cerr << "lidarloop: note: " << log << " has " << recorded.size() << " " << topics::localizer_status
              << " messages, the replay made " << estimates.size() << " estimates\n";
    return;
  }
  for (size_t i = 0; i < estimates.size(); ++i)
    if (encode_localizer_status(localizer_status(estimates[i])) != recorded[i]) {
      std::cerr << "lidarloop: note: the replayed localizer's status at t = " << tum_seconds(estimates[i].stamp_ns)
                << " s (scan " << i + 1 << ") differs from the one " << log << " recorded\n";
      return;
    }
  std::printf("status     the localizer's status matched the log's at all %zu scans\n", estimates.size());
}

int run_replay(const Args& args) {
  const std::string log = args.positional().at(0);
  McapReader reader(log);
  McapMessage message;
  bool more = reader.next(message);
  const RecordedRun run = recorded_run(reader, log);
  const Scenario& scenario = run.scenario;
  const std::string& recorded_method = run.method;
  std::optional<std::string> method = args.value("method");
  if (!method && !recorded_method.empty()) method = recorded_method;
  LocalizerParams params = localizer_params_for(scenario, method);
  apply_deadline_option(args, params);
  const std::string name = std::filesystem::path(run.scenario_name).stem().string();
  const std::string out = args.text("out", "out/" + name + "-replay");
  prepare_output_dir(out);  // before the replay, not after it
  if (run.vehicle_from)
    std::cerr << "lidarloop: note: " << log << " has no " << kVehicleAttachment << " (recorded by an older lidarloop): "
              << "the vehicle is read from " << *run.vehicle_from << ", which may have changed since\n";
  const auto recorded_map = run.metadata.find("map_hash");
  const std::string map_now = map_hash(scenario.world, scenario_mapping_options(scenario));
  if (recorded_map != run.metadata.end() && recorded_map->second != map_now) {
    // The map's hash also names the kernels its survey was cast with (sim/ray_scene.hpp).
    const auto recorded_isa = run.metadata.find("ray_isa");
    const std::string isa_now = ray_isa();
    std::string why = "its world, materials or actors changed";
    if (recorded_isa == run.metadata.end())
      why = "it was recorded before logs named their ray-casting kernels, or its world, materials or actors changed";
    else if (recorded_isa->second != isa_now)
      why = "its scans were cast with " + recorded_isa->second + " kernels and this machine's map with " + isa_now;
    std::cerr << "lidarloop: note: the map of world '" << scenario.world << "' is not the one " << log
              << " was recorded with (hash " << map_now << ", recorded " << recorded_map->second << "): " << why
              << ", and the estimates may differ from the run's\n";
  }
  const LoadedWorld world = load_scenario_world(scenario);
  const ResolvedScenario resolved = resolve_scenario(scenario, world.description, world.world);
  HdMap map = open_scenario_map(scenario, world);

  LocalizerBackend localizer(map, params, scenario);
  const Hdl32eCalibration calibration = scenario.lidar.calibration();
  std::vector<TruthSample> truth;
  std::vector<LocalizerEstimate> estimates;
  std::optional<GpsFix> pending;  // a fix waits for its heading, recorded right after it
  auto flush_gps = [&] {
    if (pending) localizer.on_gps(*pending);
    pending.reset();
  };
  size_t scans = 0;
  std::vector<CurbVisibility> curb_visibility;
  std::vector<ros2::Bytes> recorded_statuses;
  for (; more; more = reader.next(message)) {
    const std::string& topic = message.channel->topic;
    const std::string context = log + " " + topic;
    if (topic == topics::gps_heading && pending) {
      const ros2::GnssHeading h = ros2::decode_gnss_heading(message.data, context);
      if (h.stamp_ns == pending->stamp_ns) {
        pending->heading_rad = h.heading;
        pending->heading_variance = h.variance;
      }
      flush_gps();
      continue;
    }
    flush_gps();
    if (topic == topics::vehicle_report) {
      localizer.on_can(ros2::decode_vehicle_report(message.data, context));
    } else if (topic == topics::gps_fix) {
      pending = ros2::decode_nav_sat_fix(message.data, context);
    } else if (topic == topics::truth_state) {
      truth.push_back(ros2::decode_truth_state(message.data, context));
    } else if (topic == topics::truth_curb_visibility) {
      curb_visibility.push_back(ros2::decode_curb_visibility(message.data, context));
    } else if (topic == topics::localizer_status) {
      recorded_statuses.emplace_back(message.data.begin(), message.data.end());
    } else if (std::optional<PointCloud> scan = scan_message(reader, message, calibration)) {
      estimates.push_back(localizer.on_scan(*scan));
      ++scans;
    }
  }
  flush_gps();
  std::string failure;  // a program that fails after its last answer: its answers are still scored
  try {
    localizer.finish();
  } catch (const InputError& e) {
    failure = e.what();
  }
  if (truth.empty()) throw InputError(log + ": no " + std::string(topics::truth_state) + " messages to score against");

  const ScoredRun scored = score_and_write(out, name, scenario, resolved.ego_route, truth, method_label(params),
                                           estimates, nullptr, map, curb_visibility, failure);
  std::cout << comparison_markdown({scored.metrics});
  if (const std::string table = reference_markdown({scored.metrics}); !table.empty()) std::cout << "\n" << table;
  std::printf("\nlog        %s (%zu scans, seed %llu, recorded with %s)\n", log.c_str(), scans,
              (unsigned long long)scenario.seed, recorded_method.empty() ? "no localizer" : recorded_method.c_str());
  std::printf("latency    %s\n", latency_text(scored.metrics).c_str());
  std::printf("curbs      %s\n", curb_occlusion_text(scored.metrics).c_str());
  std::cout << integrity_lines(scored.metrics);
  std::cout << reference_lines(scored.metrics);
  if (method == recorded_method) compare_statuses(log, recorded_statuses, estimates);
  for (const auto& f : scored.metrics.failures) std::printf("FAILED     %s\n", f.c_str());
  std::printf(
      "result     %s\nfiles      %s/ (metrics.json, errors.csv, estimate.tum, truth.tum%s, junit.xml, errors.png, "
      "trajectory.png)\n",
      scored.metrics.pass ? "PASS" : "FAIL", out.c_str(), scored.metrics.reference ? ", reference.tum" : "");
  if (!failure.empty()) throw InputError(failure + " (the replay's results are in " + out + "/, failed)");
  return scored.metrics.pass ? 0 : 1;
}

}  // namespace

Command replay_command() {
  return {
      {"replay",
       "lidarloop replay FILE.mcap [--method NAME|exec:PROGRAM ARGS] [--out DIR]",
       "Feed a log recorded by `run --record` or `simulate --record` to the localizer and score it\n"
       "against the recorded ground truth, with the recorded scenario's thresholds. With the recorded\n"
       "method, the estimates are the live run's, bit for bit. Exit codes as for run.",
       {{"method", "NAME", "localizer method, or exec:PROGRAM ARGS (default: the recorded one, else the scenario's)"},
        {"deadline-ms", "MS", "an exec: localizer's per-scan deadline (default: the recorded scenario's, else 100)"},
        {"out", "DIR", "output folder (default out/<scenario name>-replay)"}},
       1,
       1},
      run_replay};
}

}  // namespace lidarloop
