// lidarloop run / compare: a scenario with the localizer in the loop, scored against ground truth.
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>

#include "common/input_error.hpp"
#include "common/output_dir.hpp"
#include "common/units.hpp"
#include "loop/localizer_loop.hpp"
#include "loop/localizer_setup.hpp"
#include "loop/run_outputs.hpp"
#include "loop/run_recording.hpp"
#include "scoring/paper_tables.hpp"
#include "scoring/result_files.hpp"
#include "sim/sensor_calibration.hpp"
#include "sweep/sweep_plan.hpp"
#include "tools/commands.hpp"
#include "tools/scene_setup.hpp"

namespace lidarloop {
namespace {

// A scan "has an obstacle in the corridor" with at least this many obstacle points (a pedestrian at
// 30 m gives a few dozen; stray returns a handful).
constexpr size_t kObstacleScanPoints = 20;

// The scenario named on the command line, with --seed and --duration applied.
LoadedScenario load_with_overrides(const Args& args) {
  LoadedScenario s = load_scenario_and_world(args.positional().at(0), realism_option(args));
  if (args.value("seed")) s.scenario.seed = uint64_t(args.integer("seed", 0, 0, 1L << 62));
  if (args.value("duration")) s.scenario.duration_s = args.number("duration", s.scenario.duration_s);
  if (s.scenario.duration_s <= 0) throw InputError("--duration must be positive");
  return s;
}

// The realism profile and the knobs the scenario sets on top of it.
// `mount`: also the LiDAR mount error drawn for the scenario's seed (one run's).
void print_realism(const Scenario& s, bool mount = true) {
  const std::vector<std::string> overrides = realism_overrides(s);
  std::printf("realism    %s%s\n", realism_name(s.realism),
              overrides.empty() ? ", no knob overridden" : ", with the scenario's own settings:");
  for (const auto& o : overrides) std::printf("           %s\n", o.c_str());
  if (!mount) return;
  const MountDraw m = draw_mount_error(s.mount_error, s.seed);
  const Eigen::Vector3d rpy = m.lidar_rpy_rad * kDegPerRad, xyz = m.lidar_xyz_m * 1e3;
  std::printf(
      "mount      the LiDAR's true mount against the nominal one the localizer is given: roll %.3f, "
      "pitch %.3f, yaw %.3f deg; x %.1f, y %.1f, z %.1f mm\n",
      rpy.x(), rpy.y(), rpy.z(), xyz.x(), xyz.y(), xyz.z());
}

// The accuracy against the truth and against the reference side by side, after the score table;
// nothing when no run has a reference, so such a run prints what it always did.
void print_reference_table(const std::vector<Metrics>& metrics) {
  const std::string table = reference_markdown(metrics);
  if (!table.empty()) std::cout << "\n" << table;
}

// The paper's table again with ours against the reference, as the paper's own figures were measured
// against its RTK GPS; empty when no run has a reference.
std::string paper_reference_markdown(PaperTable table, const std::vector<Metrics>& metrics) {
  const std::vector<MethodOverSeeds> ours = summarise_over_seeds(metrics, true);
  if (ours.empty()) return "";
  return "\nours against the reference (the paper's against its RTK GPS):\n" + paper_comparison_markdown(table, ours);
}

struct Progress {
  bool terminal = isatty(STDOUT_FILENO) != 0;
  std::string what;
  double duration_s = 0;
  void operator()(double fraction) const {
    if (!terminal) return;
    std::printf("\r%s %3d%%  %.1f of %.1f s", what.c_str(), int(fraction * 100), fraction * duration_s, duration_s);
    std::fflush(stdout);
  }
  void clear() const {
    if (terminal) std::printf("\r%70s\r", "");
  }
};

// In closed loop: when the estimates reached the controller, after their scans.
std::string controller_latency_text(const LatencyParams& model, const std::vector<double>& delays_ms) {
  if (delays_ms.empty()) return "no estimate reached the controller";
  char text[160];
  std::snprintf(text, sizeof text,
                "the controller got each estimate %.1f ms (p50), at most %.1f ms, after its scan (%s)",
                percentile_nearest_rank(delays_ms, 50), *std::max_element(delays_ms.begin(), delays_ms.end()),
                latency_text(model).c_str());
  return text;
}

int run_run(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  LoadedScenario s = load_with_overrides(args);
  if (auto loop = args.value("loop")) {
    if (*loop != "open" && *loop != "closed") throw InputError("--loop must be open or closed, got '" + *loop + "'");
    s.scenario.closed_loop = *loop == "closed";
  }
  LocalizerParams params = localizer_params_for(s.scenario, args.value("method"));
  apply_deadline_option(args, params);
  if (const auto latency = args.value("latency")) {
    try {
      params.latency = parse_latency(*latency);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--latency: ") + e.what());
    }
  }
  const bool external = !params.external.command.empty();
  const std::string name = std::filesystem::path(s.scenario.file).stem().string();
  const std::string out = args.text("out", "out/" + name);
  // Every output is opened before the map and the run: one that cannot be written fails at once.
  prepare_output_dir(out);
  const std::unique_ptr<RecordingSink> recorder =
      start_recording(args.value("record"), s.scenario, method_text(params), scan_recording_option(args));

  HdMap map = open_scenario_map(s.scenario, s.world);
  Simulation sim(s.scenario, s.world.description, s.world.world, s.world.materials, actors_dir(), threads);
  const Progress progress{isatty(STDOUT_FILENO) != 0, "run " + method_label(params), s.scenario.duration_s};
  std::function<void(const LocalizerEstimate&)> log_estimate;
  if (recorder) log_estimate = [&](const LocalizerEstimate& e) { record_estimate(recorder->log(), e); };
  const LoopResult r =
      run_localizer_loop(sim, map, {params}, s.scenario.closed_loop, recorder.get(), std::ref(progress), log_estimate);
  if (recorder) recorder->log().close();
  progress.clear();

  const MethodTrace& trace = r.methods.front();
  const ScoredRun scored = score_and_write(out, name, s.scenario, sim.resolved().ego_route, r.truth, trace.method,
                                           trace.estimates, &trace.worst, map, r.curb_visibility, trace.failure);
  const Metrics& m = scored.metrics;
  std::cout << comparison_markdown({m});
  print_reference_table({m});
  std::printf("\nscenario   %s (seed %llu, %s loop), %.1f s simulated in %.1f s wall (%.1fx real time, %d thread(s))\n",
              s.scenario.file.c_str(), (unsigned long long)s.scenario.seed, s.scenario.closed_loop ? "closed" : "open",
              s.scenario.duration_s, r.wall_s, s.scenario.duration_s / r.wall_s, threads);
  print_realism(s.scenario);
  std::printf("localizer  %zu scans, %.2f ms per scan on average, %.1f%% of the loop's time\n", r.scans,
              1e3 * r.localizer_wall_s / double(std::max<size_t>(r.scans, 1)), 100 * r.localizer_wall_s / r.wall_s);
  std::printf("latency    %s\n", latency_text(m).c_str());
  if (s.scenario.closed_loop)
    std::printf("           %s\n", controller_latency_text(controller_latency(params), r.controller_delays_ms).c_str());
  std::printf("lane       the car stayed within %.2f m of its lane's centre\n", m.max_lane_offset_m);
  std::printf("coverage   %.1f%% of the drive had an estimate (largest gap %.2f s)\n", 100 * m.coverage,
              m.largest_gap_s);
  if (!external) {  // an outside program does not say which points it took for obstacles
    size_t with_obstacles = 0;
    for (const auto& e : trace.estimates) with_obstacles += e.obstacle_points >= kObstacleScanPoints;
    std::printf("obstacles  in the corridor in %zu of %zu scans (%.0f%%)\n", with_obstacles, trace.estimates.size(),
                100.0 * double(with_obstacles) / double(std::max<size_t>(trace.estimates.size(), 1)));
  }
  std::printf("curbs      %s\n", curb_occlusion_text(m).c_str());
  std::cout << integrity_lines(m);
  std::cout << reference_lines(m);
  for (const auto& f : m.failures) std::printf("FAILED     %s\n", f.c_str());
  std::printf(
      "result     %s\nfiles      %s/ (metrics.json, errors.csv, estimate.tum, truth.tum%s, junit.xml, errors.png, "
      "trajectory.png, worst_frame.png)\n",
      m.pass ? "PASS" : "FAIL", out.c_str(), m.reference ? ", reference.tum" : "");
  if (!trace.failure.empty()) throw InputError(trace.failure + " (the run's results are in " + out + "/, failed)");
  return m.pass ? 0 : 1;
}

std::vector<std::string> parse_methods(const std::string& list) {
  if (list == "all") return localizer_method_names();
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string m; std::getline(ss, m, ',');) {
    if (m.empty()) throw InputError("--methods: empty method name in '" + list + "'");
    out.push_back(m);
  }
  return out;
}

// The paper's claim as a check: `method` is at least as good as every other on each of the three
// RMSEs. Exit 1 (and say where) when it is not.
int expect_best(const std::vector<Metrics>& metrics, const std::string& method) {
  const auto it = std::find_if(metrics.begin(), metrics.end(), [&](const Metrics& m) { return m.method == method; });
  if (it == metrics.end()) throw InputError("--expect-best: method '" + method + "' is not among those compared");
  bool best = true;
  for (const Metrics& other : metrics) {
    if (other.method == method) continue;
    const std::pair<const char*, std::pair<double, double>> rows[] = {
        {"lateral RMSE", {it->lateral_rmse_m, other.lateral_rmse_m}},
        {"longitudinal RMSE", {it->longitudinal_rmse_m, other.longitudinal_rmse_m}},
        {"heading RMSE", {it->heading_rmse_deg, other.heading_rmse_deg}}};
    for (const auto& [what, values] : rows)
      if (!(values.first <= values.second)) {
        std::printf("NOT BEST   %s: %s %.3f > %s %.3f\n", what, method.c_str(), values.first, other.method.c_str(),
                    values.second);
        best = false;
      }
  }
  std::printf("result     %s %s\n", method.c_str(),
              best ? "is at least as good as every other method on each RMSE" : "is not the best on every RMSE");
  return best ? 0 : 1;
}

// Every method on one simulated drive of `s` (its own seed); each method's files under `out`.
std::vector<Metrics> compare_once(const LoadedScenario& s, const std::vector<std::string>& methods, int threads,
                                  const std::string& out, size_t& scans, const Args& args) {
  std::vector<LocalizerParams> params;
  for (const auto& m : methods) {
    params.push_back(localizer_params_for(s.scenario, m));
    apply_deadline_option(args, params.back());
  }
  const std::string name = std::filesystem::path(s.scenario.file).stem().string();
  prepare_output_dir(out);
  HdMap map = open_scenario_map(s.scenario, s.world);
  // Open loop: every method sees the same drive; in closed loop each would drive its own.
  Simulation sim(s.scenario, s.world.description, s.world.world, s.world.materials, actors_dir(), threads);
  const Progress progress{isatty(STDOUT_FILENO) != 0, "compare seed " + std::to_string(s.scenario.seed),
                          s.scenario.duration_s};
  const LoopResult r = run_localizer_loop(sim, map, params, false, nullptr, std::ref(progress));
  progress.clear();
  scans = r.scans;

  std::vector<Metrics> metrics;
  for (const auto& trace : r.methods)
    metrics.push_back(score_and_write(out + "/" + trace.method, name, s.scenario, sim.resolved().ego_route, r.truth,
                                      trace.method, trace.estimates, &trace.worst, map, r.curb_visibility,
                                      trace.failure)
                          .metrics);
  write_junit(out + "/junit.xml", metrics);
  write_comparison_csv(out + "/comparison.csv", metrics);
  const std::string reference_table = reference_markdown(metrics);
  write_text_file(out + "/comparison.md",
                  comparison_markdown(metrics) + (reference_table.empty() ? "" : "\n" + reference_table));
  for (const auto& trace : r.methods)
    if (!trace.failure.empty())
      throw InputError(trace.failure + " (the comparison's results are in " + out + "/, " + trace.method + " failed)");
  return metrics;
}

int run_compare(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  LoadedScenario s = load_with_overrides(args);
  // --methods' list, then every --method (an exec: command line may hold commas).
  std::vector<std::string> methods = args.values("method");
  if (args.value("methods") || methods.empty()) {
    std::vector<std::string> listed = parse_methods(args.text("methods", "all"));
    methods.insert(methods.begin(), listed.begin(), listed.end());
  }
  std::optional<PaperTable> paper;
  if (const auto word = args.value("paper")) {
    paper = parse_paper_table(*word);
    if (!paper) throw InputError("--paper must be static or dynamic, got '" + *word + "'");
  }
  const std::string name = std::filesystem::path(s.scenario.file).stem().string();
  const std::string out = args.text("out", "out/" + name + "-compare");
  prepare_output_dir(out);
  const auto expect = args.value("expect-best");

  if (!args.value("seeds")) {
    size_t scans = 0;
    const std::vector<Metrics> metrics = compare_once(s, methods, threads, out, scans, args);
    std::cout << comparison_markdown(metrics);
    print_reference_table(metrics);
    if (paper)
      std::cout << "\n"
                << paper_comparison_markdown(*paper, summarise_over_seeds(metrics))
                << paper_reference_markdown(*paper, metrics);
    std::printf("\nscenario   %s (seed %llu), %.1f s, %zu scans, %zu methods on the same streams\n",
                s.scenario.file.c_str(), (unsigned long long)s.scenario.seed, s.scenario.duration_s, scans,
                metrics.size());
    print_realism(s.scenario);
    if (!metrics.empty()) std::printf("curbs      %s\n", curb_occlusion_text(metrics.front()).c_str());  // one drive
    for (const Metrics& m : metrics) std::cout << integrity_lines(m, m.method);
    for (const Metrics& m : metrics) std::cout << reference_lines(m, m.method);
    std::printf("files      %s/ (comparison.md, comparison.csv, junit.xml, <method>/...)\n", out.c_str());
    return expect ? expect_best(metrics, *expect) : 0;
  }

  // Several seeds: one drive each, then every method's mean and spread over them.
  std::vector<Metrics> all;
  int status = 0;
  for (const uint64_t seed : parse_seed_list(*args.value("seeds"), "--seeds")) {
    s.scenario.seed = seed;
    size_t scans = 0;
    const std::vector<Metrics> metrics =
        compare_once(s, methods, threads, out + "/seed_" + std::to_string(seed), scans, args);
    all.insert(all.end(), metrics.begin(), metrics.end());
    std::printf("seed %-5llu %zu scans:", (unsigned long long)seed, scans);
    for (const Metrics& m : metrics)
      std::printf(" %s %.3f/%.3f/%.3f", m.method.c_str(), m.lateral_rmse_m, m.longitudinal_rmse_m, m.heading_rmse_deg);
    if (!metrics.empty() && std::isfinite(metrics.front().curb_hidden_fraction))  // the same drive for every method
      std::printf("; curbs hidden %.1f%%", 100 * metrics.front().curb_hidden_fraction);
    std::printf("\n");
    if (expect && expect_best(metrics, *expect) != 0) status = 1;
  }
  const std::vector<MethodOverSeeds> summary = summarise_over_seeds(all);
  const PaperTable beside = paper.value_or(PaperTable::dynamic_campus);
  const std::string table = paper_comparison_markdown(beside, summary) + paper_reference_markdown(beside, all);
  write_comparison_csv(out + "/comparison.csv", all);
  write_text_file(out + "/seeds.md", table);
  std::cout << "\n" << table;
  std::printf("\nscenario   %s, %zu seeds (--seeds %s), %.1f s each; ours: mean (smallest-largest) over the seeds%s\n",
              s.scenario.file.c_str(), all.size() / std::max<size_t>(methods.size(), 1), args.value("seeds")->c_str(),
              s.scenario.duration_s, paper ? "" : "; paper: Table III (give --paper static for Table II)");
  print_realism(s.scenario, false);  // each seed drew its own mount error (metrics.json)
  std::printf("files      %s/ (seeds.md, comparison.csv, seed_<N>/...)\n", out.c_str());
  return status;
}

}  // namespace

Command run_command() {
  return {{"run",
           "lidarloop run SCENARIO.yaml [--method NAME] [--loop open|closed] [--out DIR] [--seed N]\n"
           "                    [--record FILE.mcap [--packets|--packets-only]]",
           "Run a scenario with the localizer in the loop and score it against ground truth. Writes\n"
           "metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml and plots to DIR. Exit 0 when\n"
           "every threshold of the scenario's `pass` holds, 1 when one fails, 2 on bad input.",
           {{"method", "NAME",
             method_name_list() + ", or exec:PROGRAM ARGS (docs/external-localizer.md); default: the scenario's"},
            {"loop", "open|closed", "closed: the controller steers on the estimate (default: the scenario's)"},
            {"out", "DIR", "output folder (default out/<scenario name>)"},
            {"seed", "N", "override the scenario's seed"},
            {"realism", "PROFILE", "ideal, typical or harsh: replaces the scenario's realism profile"},
            {"duration", "S", "override the scenario's duration, seconds"},
            {"deadline-ms", "MS", "an exec: localizer's per-scan deadline (default: the scenario's, else 100)"},
            {"latency", "MODEL",
             "closed loop: when an estimate reaches the controller: one_scan, measured or MS per scan\n"
             "(default: the scenario's localizer.latency; measured for exec:, one_scan for built-in methods)"},
            {"record", "FILE.mcap", "record every stream and the estimates as an MCAP log (replay redoes the run)"},
            {"packets", "", "with --record: also log the HDL-32E's raw UDP packets on /velodyne_packets"},
            {"packets-only", "",
             "with --record: log the scans only as the HDL-32E's packets (the sensor's own data rate; "
             "replay and export decode them)"},
            {"threads", "N", "worker threads (default: all cores)"}},
           1,
           1},
          run_run};
}

Command compare_command() {
  return {
      {"compare",
       "lidarloop compare SCENARIO.yaml [--methods all|a,b,c] [--method exec:PROGRAM ARGS]... [--expect-best NAME]\n"
       "                        [--out DIR] [--seed N] [--seeds LIST] [--paper static|dynamic] [--realism PROFILE]",
       "Simulate a scenario once and feed the identical streams to several localizer methods; print\n"
       "and write a table like the paper's Table III (comparison.md, comparison.csv).",
       {{"methods", "LIST", "all, or a comma-separated list of methods (default all, unless --method is given)"},
        {"method", "NAME", "one more method, repeatable: a name or exec:PROGRAM ARGS (docs/external-localizer.md)"},
        {"expect-best", "NAME", "exit 1 unless this method has the lowest lateral, longitudinal and heading RMSE"},
        {"deadline-ms", "MS", "an exec: localizer's per-scan deadline (default: the scenario's, else 100)"},
        {"seeds", "LIST", "run every seed of a list (1,2,3) or range (1-5); print each method's mean and spread"},
        {"paper", "TABLE", "print the paper's Table II (static) or III (dynamic) beside ours"},
        {"out", "DIR", "output folder (default out/<scenario name>-compare)"},
        {"seed", "N", "override the scenario's seed"},
        {"realism", "PROFILE", "ideal, typical or harsh: replaces the scenario's realism profile"},
        {"duration", "S", "override the scenario's duration, seconds"},
        {"threads", "N", "worker threads (default: all cores)"}},
       1,
       1},
      run_compare};
}

void apply_deadline_option(const Args& args, LocalizerParams& params) {
  if (!args.value("deadline-ms")) return;
  constexpr double kMaxDeadlineMs = 60000;  // a minute per scan: beyond it, a typo
  const double ms = args.number("deadline-ms", params.external.deadline_ms);
  if (!(ms > 0 && ms <= kMaxDeadlineMs)) throw InputError("--deadline-ms must be above 0 and at most 60000");
  params.external.deadline_ms = ms;
}

ScanRecording scan_recording_option(const Args& args) {
  const bool packets = args.flag("packets"), only = args.flag("packets-only");
  if (packets && only) throw InputError("--packets and --packets-only: give one of them");
  return only ? ScanRecording::packets : packets ? ScanRecording::points_and_packets : ScanRecording::points;
}

}  // namespace lidarloop
