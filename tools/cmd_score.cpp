// lidarloop score: the trajectory of a localizer that is not ours (a ROS 2 node, a prototype, a
// vendor binary), scored against a log recorded by `run --record` or `simulate --record`, with the
// same metrics, files and verdict as `run` (loop/run_outputs.hpp writes them for both). The
// estimate is aligned to the truth by time stamp only (scoring/scorer.hpp); thresholds are the log's
// scenario's `pass`, then a --pass file's, then each --threshold.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "logs/log_topics.hpp"
#include "logs/tum_file.hpp"
#include "loop/fault_events.hpp"
#include "loop/localizer_setup.hpp"
#include "loop/recorded_log.hpp"
#include "loop/run_outputs.hpp"
#include "scoring/estimate_file.hpp"
#include "scoring/result_files.hpp"
#include "sim/world_assets.hpp"
#include "tools/commands.hpp"

namespace lidarloop {
namespace {

// The thresholds: the recorded scenario's, then --pass FILE's, then every --threshold in order.
PassThresholds thresholds_for(const Args& args, PassThresholds pass) {
  if (const auto file = args.value("pass")) pass = load_pass_file(*file, pass);
  for (const std::string& t : args.values("threshold")) pass = parse_pass_assignment(t, "--threshold", pass);
  return pass;
}

// Bad input rather than a run that fails: nothing of the estimate lies within the recorded drive.
void check_overlap(const std::string& file, const std::vector<EstimateRecord>& estimates, const std::string& log,
                   const std::vector<TruthPose>& truth) {
  const int64_t first = truth.front().stamp_ns, last = truth.back().stamp_ns;
  for (const EstimateRecord& e : estimates)
    if (e.stamp_ns >= first && e.stamp_ns <= last) return;
  throw InputError(file + ": every estimate (t = " + tum_seconds(estimates.front().stamp_ns) + " to " +
                   tum_seconds(estimates.back().stamp_ns) + " s) lies outside the ground truth of " + log + " (" +
                   tum_seconds(first) + " to " + tum_seconds(last) + " s)");
}

// The bird's-eye picture of the worst frame needs a scan: the log's latest at or before the worst
// estimate, placed at the truth with the scenario's nominal LiDAR mount (the true mount's error, a
// tenth of a degree, does not show at the picture's scale). No detected curbs or obstacles: those
// are the localizer's own, and this one is not ours.
std::optional<WorstFrame> worst_frame(const std::string& log, const Scenario& scenario,
                                      const std::vector<TruthPose>& truth, const ScoredRun& scored) {
  if (scored.errors.empty()) return std::nullopt;
  const int64_t t = scored.metrics.worst_frame_stamp_ns;
  std::optional<PointCloud> cloud = recorded_scan_before(log, t);
  if (!cloud || cloud->stamp_ns < truth.front().stamp_ns || cloud->stamp_ns > truth.back().stamp_ns)
    return std::nullopt;
  WorstFrame w;
  w.error_m = scored.metrics.max_position_error_m;
  const Pose2d at_scan = truth_at(truth, cloud->stamp_ns);
  Eigen::Isometry3d vehicle = Eigen::Isometry3d::Identity();
  vehicle.translate(Eigen::Vector3d(at_scan.x, at_scan.y, 0));
  vehicle.rotate(Eigen::AngleAxisd(at_scan.yaw, Eigen::Vector3d::UnitZ()));
  w.sensor_pose = vehicle * scenario.lidar.mount();
  w.cloud = std::move(*cloud);
  for (const FrameError& e : scored.errors)
    if (e.stamp_ns == t) {
      w.truth = e.truth;
      w.estimate = e.estimate;
    }
  return w;
}

int run_score(const Args& args) {
  const std::string log = args.positional().at(0);
  const auto estimate_path = args.value("estimate");
  if (!estimate_path) throw InputError("score: --estimate FILE is required (a TUM file or an MCAP)");
  // The estimate first: it is small, and a mistake in it is the likelier one.
  const EstimateFile estimate = read_estimate_file(*estimate_path, args.text("topic", ""));
  RecordedLog recorded = read_recorded_log(log);
  const std::vector<TruthPose> truth = truth_poses(recorded.truth);
  check_overlap(*estimate_path, estimate.estimates, log, truth);

  Scenario& scenario = recorded.run.scenario;
  scenario.pass = thresholds_for(args, scenario.pass);
  const LoadedWorld world = load_scenario_world(scenario);
  const ResolvedScenario resolved = resolve_scenario(scenario, world.description, world.world);
  HdMap map = open_scenario_map(scenario, world);

  const std::string name = std::filesystem::path(recorded.run.scenario_name).stem().string();
  const std::string method = args.text("method", std::filesystem::path(*estimate_path).stem().string());
  const std::string out = args.text("out", "out/" + name + "-score");
  // Scored once to find the worst frame (pure and quick), then again where the files are written.
  const std::optional<WorstFrame> worst = worst_frame(
      log, scenario, truth,
      score(truth, estimate.estimates, resolved.ego_route, scenario.pass, method, name,
            fault_events(scenario, truth.front().stamp_ns), recorded.curb_visibility, scenario.lidar.scan_period_ns()));
  const ScoredRun scored = score_and_write(out, name, scenario, resolved.ego_route, truth, method, estimate.estimates,
                                           worst ? &*worst : nullptr, map, recorded.curb_visibility);
  const Metrics& m = scored.metrics;

  std::cout << comparison_markdown({m});
  if (const std::string table = reference_markdown({m}); !table.empty()) std::cout << "\n" << table;
  std::printf("\nlog        %s (seed %llu, recorded with %s)\n", log.c_str(), (unsigned long long)scenario.seed,
              recorded.run.method.empty() ? "no localizer" : recorded.run.method.c_str());
  std::printf("estimate   %s: %s%s, %zu poses, %zu scored, %zu settling, %zu outside the truth's time range\n",
              estimate_path->c_str(), estimate.format.c_str(),
              estimate.topic.empty() ? "" : (" " + estimate.topic + " (" + estimate.type + ")").c_str(),
              estimate.estimates.size(), m.frames, m.settling_frames, m.unscored_frames);
  for (const std::string& frame : estimate.frames)
    if (frame != log_topics::map_frame)
      std::printf("note       frame_id '%s' taken as the map frame (no transform is applied)\n", frame.c_str());
  std::printf("coverage   %.1f%% of the truth's %.1f s (each estimate covers +-%.0f ms), largest gap %.2f s\n",
              100 * m.coverage, double(truth.back().stamp_ns - truth.front().stamp_ns) / double(kNsPerS),
              double(scenario.lidar.scan_period_ns()) / 2e6, m.largest_gap_s);
  std::printf("latency    not known from a file: null in metrics.json\n");
  std::printf("curbs      %s\n", curb_occlusion_text(m).c_str());
  std::cout << integrity_lines(m);
  std::cout << reference_lines(m);
  for (const auto& f : m.failures) std::printf("FAILED     %s\n", f.c_str());
  std::printf(
      "result     %s\nfiles      %s/ (metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml, errors.png, "
      "trajectory.png%s)\n",
      m.pass ? "PASS" : "FAIL", out.c_str(), worst ? ", worst_frame.png" : "; no worst_frame.png: no scan to show");
  return m.pass ? 0 : 1;
}

}  // namespace

Command score_command() {
  return {{"score",
           "lidarloop score LOG.mcap --estimate FILE [--topic TOPIC] [--out DIR] [--method LABEL]\n"
           "                      [--pass FILE.yaml] [--threshold KEY=VALUE]...",
           "Score a trajectory from any localizer against a log recorded by `run --record` or\n"
           "`simulate --record`, as `run` scores its own. The truth is interpolated at each estimate's\n"
           "stamp, with no spatial alignment; metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml\n"
           "and plots to DIR. FILE is a TUM trajectory (t x y z qx qy qz qw) or an MCAP with\n"
           "nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped (CDR, as rosbag2\n"
           "records them). Thresholds: the log's scenario's `pass`, then --pass, then --threshold.\n"
           "Exit 0 when every threshold holds, 1 when one fails, 2 on bad input.",
           {{"estimate", "FILE", "the trajectory to score: TUM or MCAP (told by its content)"},
            {"topic", "TOPIC", "MCAP: the topic to score (default: its only Odometry or PoseWithCovarianceStamped)"},
            {"out", "DIR", "output folder (default out/<scenario name>-score)"},
            {"method", "LABEL", "the name in metrics.json and the table (default: FILE's name)"},
            {"pass", "FILE.yaml", "thresholds from a file holding a `pass:` mapping, as in a scenario"},
            {"threshold", "KEY=VALUE", "one threshold (a key of `pass`, e.g. min_coverage=0.9); repeatable"}},
           1,
           1},
          run_score};
}

}  // namespace lidarloop
