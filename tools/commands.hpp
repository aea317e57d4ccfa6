#pragma once
#include <optional>
#include <string>
#include <vector>

#include "sim/realism.hpp"
#include "tools/cli_args.hpp"

namespace lidarloop {

struct Command {
  CommandSpec spec;
  int (*run)(const Args& args);
};

Command world_command();
Command scan_command();
Command bench_command();
Command validate_command();
Command simulate_command();
Command map_command();
Command info_command();
Command recover_command();
Command export_command();
Command odometry_command();
Command run_command();
Command compare_command();
Command replay_command();
Command score_command();
Command sweep_command();
int run_bench_map(const Args& args);
int run_bench_localizer(const Args& args);
int run_bench_loop(const Args& args);

// --threads N: 0 means all cores. Returns the effective count.
int thread_count(const Args& args);
struct LocalizerParams;
// --deadline-ms: an exec: localizer's per-scan deadline over the scenario's localizer.external.deadline_ms.
void apply_deadline_option(const Args& args, LocalizerParams& params);
// --realism ideal|typical|harsh, if given; InputError for any other word.
std::optional<Realism> realism_option(const Args& args);
enum class ScanRecording;  // loop/run_recording.hpp
// --packets / --packets-only: how a recorded log keeps its scans; InputError for both at once.
ScanRecording scan_recording_option(const Args& args);

}  // namespace lidarloop
