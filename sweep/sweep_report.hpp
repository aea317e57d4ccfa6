#pragma once
// What a sweep leaves behind, and the report made from it. The layout of a sweep's output folder:
//   sweep.json               the plan: axes, levels, seeds, methods, metrics, every run (identical in
//                            every shard's folder, so any of them can be merged with the others)
//   runs/<id>/scenario.yaml  the run's complete scenario
//   runs/<id>/status.json    how the run ended: done, error (bad input), crashed, timeout
//   runs/<id>/<method>/      what `run` writes (metrics.json, errors.csv, plots)
//   sweep.csv, sweep.md, plots/   the report (write_sweep_report)
// The report holds nothing that depends on where, when or how fast a run was made, so a sweep run in
// one go and the same sweep run as shards and merged give the same sweep.csv, byte for byte.
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sweep/sweep_plan.hpp"

namespace lidarloop {

// The plan as written to sweep.json: a SweepSpec's axes (without what they set) and its runs (without
// their scenario text).
struct SweepPlan {
  std::string sweep_file, digest;
  std::vector<SweepAxis> axes;
  std::vector<std::string> methods, metrics;
  std::vector<SweepRun> runs;
};
SweepPlan make_sweep_plan(const SweepSpec& spec, const std::vector<SweepRun>& runs);
std::string sweep_plan_json(const SweepPlan& plan);
// InputError naming the file when it is missing or is not a sweep plan.
SweepPlan read_sweep_plan(const std::string& path);

// How a run's process ended.
enum class RunStatus { missing, done, error, crashed, timeout };
const char* run_status_name(RunStatus s);

struct RunEnd {
  RunStatus status = RunStatus::missing;
  int exit_code = 0;  // done / error: the process's exit code
  int signal = 0;     // crashed: the signal that ended it, if any
  double wall_s = 0;  // not in the report: it differs between machines
  std::string detail;
};
std::string run_end_json(const RunEnd& end);
// The end recorded in runs/<id>/status.json, or `missing` when there is none (or it does not parse).
RunEnd read_run_end(const std::string& run_dir);

// One method's outcome in one run.
struct MethodOutcome {
  bool pass = false;
  // The sweep's metrics and curb_hidden_fraction; NaN where the run did not produce the value.
  std::map<std::string, double> metrics;
};
struct RunResult {
  RunEnd end;
  std::map<std::string, MethodOutcome> methods;  // only for runs that are done
};
// Reads a run's status and each method's metrics.json; a run marked done whose metrics are missing or
// unreadable is reported as crashed (it did not finish what it started).
RunResult read_run_result(const std::string& run_dir, const SweepRun& run, const std::vector<std::string>& metrics);

// Writes sweep.csv, sweep.md and plots/ into `dir` from the plan and a result per run (in the plan's
// order).
void write_sweep_report(const std::string& dir, const SweepPlan& plan, const std::vector<RunResult>& results);
// The same CSV as a string (one row per run and method).
std::string sweep_csv(const SweepPlan& plan, const std::vector<RunResult>& results);

}  // namespace lidarloop
