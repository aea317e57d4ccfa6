#pragma once
// A stress sweep: one base scenario, a grid of variations, seeds and methods (scenarios/sweeps/*.yaml).
// Loading checks the file like a scenario (file:line:col); expanding gives the runs, each with its
// own complete scenario text, in an order that never depends on where or how the runs are executed,
// so shard I of N is the same set of runs on any machine.
//
//   scenario: ../bus_occlusion.yaml        # the base, relative to the sweep file
//   seeds: 1-5                             # or a list
//   methods: [proposed, icp]               # default: the scenario's own
//   metrics: [lateral_rmse_m, ...]         # what the report tabulates and plots
//   timeout_s: 600                         # a run still going after this is stopped, recorded as such
//   grid:                                  # one run for every combination of the axes' levels
//     - {name: side, levels: {right: -1, left: 1}}        # named levels with numbers
//     - {name: gap_m, values: [0.5, 1.0, 2.0]}             # numbers or words
//     - {name: alongside_s, range: {from: 5, to: 25, step: 10}}
//     - {path: traffic[0].speed, values: [5, 10]}           # a value set into the scenario directly
//     - {name: lane, zip: {traffic[0].path.lane: [right, left], traffic[0].path.backward: [false, true]}}
//   set:                                   # scenario values derived from the axes, in this order
//     traffic[0].path.offset: side * (4.5 - gap_m - 1.25)
//   copies: {of: traffic[0], count: coaches, shift: {start_at: 15}}   # repeat a list entry
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace lidarloop {

// One level of an axis: how it is shown, its number (NaN for a word) and what it sets.
struct SweepLevel {
  std::string label;
  double value = 0;
  std::vector<std::pair<std::string, YAML::Node>> sets;  // scenario path -> scalar
};

struct SweepAxis {
  std::string name;  // a name expressions can use, or the path it sets
  std::string where;
  std::vector<SweepLevel> levels;
  bool numeric() const;  // every level has a number: plotted on a number line
};

struct SweepSet {
  std::string path, expression, where;
};

struct SweepCopies {
  std::string of;     // a path to a list entry, e.g. traffic[0]
  std::string count;  // an expression: how many there are in all (1: just the original; 0: none)
  std::vector<std::pair<std::string, double>> shift;  // path within the entry -> added per copy
  std::string where;
};

struct SweepSpec {
  std::string file, text;
  std::string scenario_file, scenario_text;  // the base
  std::vector<uint64_t> seeds;
  std::vector<std::string> methods;
  std::vector<std::string> metrics;
  double timeout_s = 0;
  std::vector<SweepAxis> axes;
  std::vector<SweepSet> sets;
  std::optional<SweepCopies> copies;
  bool closed_loop = false;  // the base scenario's loop: each closed-loop method drives its own run
};

// One process of the sweep: a grid point, a seed, and the methods that run on its one simulated drive
// (open loop: all of them, as `compare` does; closed loop: one).
struct SweepRun {
  size_t index = 0;
  std::string id;             // folder name under runs/, fixed width
  std::vector<size_t> level;  // per axis, the index of its level
  uint64_t seed = 0;
  std::vector<std::string> methods;
  std::string scenario_text;  // the complete scenario of this run
};

// InputError naming file:line:col for anything wrong: unknown keys, an axis without levels, a path
// that is not in the scenario, an unknown parameter in an expression, a method or metric that does not
// exist.
SweepSpec load_sweep(const std::string& path);

// Every run in order: axes outermost first (the first axis varies slowest), then seeds, then methods.
// InputError naming the run and its levels when a run's scenario does not load.
std::vector<SweepRun> expand_sweep(const SweepSpec& spec);

// The metric names a sweep can tabulate (fields of a run's metrics.json).
const std::vector<std::string>& sweep_metric_names();

// A digest of everything the runs are made from: outputs of sweeps with another digest do not mix.
std::string sweep_digest(const SweepSpec& spec);

// Seeds as a list "1,2,5" or a range "1-5" (at most kMaxSeeds of them); InputError naming `what`.
constexpr size_t kMaxSeeds = 1000;  // a typo's guard, not a limit of the method
std::vector<uint64_t> parse_seed_list(const std::string& text, const std::string& what);

// Shard `index` of `count`: runs whose index is `index` modulo `count`.
struct Shard {
  size_t index = 0, count = 1;
  bool contains(size_t run) const { return run % count == index; }
};
// "I/N" with 0 <= I < N.
Shard parse_shard(const std::string& text);

}  // namespace lidarloop
