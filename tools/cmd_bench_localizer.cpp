// lidarloop bench localizer / loop.
//   localizer: a campus drive is simulated once into memory, then replayed into the localizer at one
//              thread and at two; per-stage and total latency percentiles per scan, as JSON.
//   loop:      the whole closed loop (simulation + localizer) against the wall clock, as JSON.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <variant>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "loop/kidnap_schedule.hpp"
#include "loop/localizer_loop.hpp"
#include "loop/localizer_setup.hpp"
#include "scoring/scorer.hpp"
#include "tools/commands.hpp"
#include "tools/scene_setup.hpp"

namespace lidarloop {
namespace {

// The localizer's inputs, in the order the simulation emitted them.
using Message = std::variant<CanFrame, GpsFix, PointCloud>;

class MemorySink : public StreamSink {
 public:
  std::vector<Message> messages;
  size_t scans = 0;
  void on_can(const CanFrame& f) override { messages.emplace_back(f); }
  void on_gps(const GpsFix& f) override { messages.emplace_back(f); }
  void on_scan(const PointCloud& c, const Eigen::Isometry3d&) override {
    messages.emplace_back(c);
    ++scans;
  }
};

constexpr int kWarmupScans = 10;  // the accumulator fills and the first map tiles load

nlohmann::json percentiles(const std::vector<double>& ms) {
  return {{"p50", percentile_nearest_rank(ms, 50)},
          {"p99", percentile_nearest_rank(ms, 99)},
          {"max", percentile_nearest_rank(ms, 100)}};
}

// `kidnaps`: the scenario's, done as in the loop, so a kidnap's relocalization is in the latency.
nlohmann::json replay(const std::vector<Message>& messages, HdMap& map, const LocalizerParams& params,
                      KidnapSchedule kidnaps, int threads) {
  const auto limit = limit_threads(threads);
  Localizer localizer(map, params);
  std::vector<std::vector<double>> stage(kStageCount);
  std::vector<double> total, wide_search;
  size_t scans = 0, degraded = 0;
  for (const Message& m : messages) {
    if (const auto* c = std::get_if<CanFrame>(&m)) localizer.on_can(*c);
    if (const auto* g = std::get_if<GpsFix>(&m)) localizer.on_gps(*g);
    if (const auto* s = std::get_if<PointCloud>(&m)) {
      for (const Pose2d& offset : kidnaps.due(s->stamp_ns)) localizer.displace(offset);
      const LocalizerEstimate e = localizer.on_scan(*s);
      // A cold start's searches fall in the warm-up: they are timed all the same (tile loads included).
      if (e.wide_search) wide_search.push_back(e.total_ms);
      if (++scans <= kWarmupScans) continue;
      for (int k = 0; k < kStageCount; ++k) stage[size_t(k)].push_back(e.stage_ms[size_t(k)]);
      total.push_back(e.total_ms);
      degraded += e.health != 0;
    }
  }
  nlohmann::json stages;
  for (int k = 0; k < kStageCount; ++k) stages[stage_name(Stage(k))] = percentiles(stage[size_t(k)]);
  return {{"threads", threads},
          {"scans_timed", total.size()},
          {"scans_degraded", degraded},
          {"total_ms", percentiles(total)},
          {"scans_wide_search", wide_search.size()},
          {"wide_search_total_ms", percentiles(wide_search)},
          {"stages_ms", stages}};
}

std::string default_scenario() { return data_dir() + "/scenarios/campus_traffic.yaml"; }

int bench_localizer(const Args& args) {
  LoadedScenario s = load_scenario_and_world(args.text("scenario", default_scenario()));
  s.scenario.duration_s = args.number("duration", 20.0);
  if (s.scenario.duration_s <= 0) throw InputError("--duration must be positive");
  const LocalizerParams params = localizer_params_for(s.scenario, args.value("method"));
  // A map of its own for each run, so both start with no tiles loaded (loading one is in the latency).
  HdMap map_1 = open_scenario_map(s.scenario, s.world), map_2 = open_scenario_map(s.scenario, s.world);

  MemorySink recorded;
  {
    const int sim_threads = thread_count(args);
    const auto limit = limit_threads(sim_threads);
    Simulation sim(s.scenario, s.world.description, s.world.world, s.world.materials, actors_dir(), sim_threads);
    sim.run(recorded);
  }
  const nlohmann::json result = {{"benchmark", "localizer"},
                                 {"scenario", s.scenario.file},
                                 {"method", method_name(params.method)},
                                 {"scans", recorded.scans},
                                 {"budget_ms", {{"p50", 8.0}, {"p99", 20.0}}},
                                 {"runs",
                                  {replay(recorded.messages, map_1, params, KidnapSchedule(s.scenario), 1),
                                   replay(recorded.messages, map_2, params, KidnapSchedule(s.scenario), 2)}}};
  std::cout << result.dump(2) << "\n";
  return 0;
}

// Open and closed loop on the same scenario, one after the other, each with its own map so that both
// pay for their tile loads (the localizer runs beside the simulation in both).
int bench_loop(const Args& args) {
  const int threads = thread_count(args);
  const auto limit = limit_threads(threads);
  LoadedScenario s = load_scenario_and_world(args.text("scenario", default_scenario()));
  s.scenario.duration_s = args.number("duration", 20.0);
  if (s.scenario.duration_s <= 0) throw InputError("--duration must be positive");
  const LocalizerParams params = localizer_params_for(s.scenario, args.value("method"));
  nlohmann::json runs = nlohmann::json::array();
  for (const bool closed : {false, true}) {
    HdMap map = open_scenario_map(s.scenario, s.world);
    Simulation sim(s.scenario, s.world.description, s.world.world, s.world.materials, actors_dir(), threads);
    const LoopResult r = run_localizer_loop(sim, map, {params}, closed);
    runs.push_back({{"loop", closed ? "closed" : "open"},
                    {"wall_s", r.wall_s},
                    {"realtime_factor", s.scenario.duration_s / r.wall_s},
                    {"localizer_busy_share", r.localizer_wall_s / r.wall_s},
                    {"scans", r.scans}});
  }
  const nlohmann::json result = {
      {"benchmark", "loop"}, {"scenario", s.scenario.file},          {"method", method_name(params.method)},
      {"threads", threads},  {"simulated_s", s.scenario.duration_s}, {"budget_realtime_factor", 10.0},
      {"runs", runs}};
  std::cout << result.dump(2) << "\n";
  return 0;
}

}  // namespace

int run_bench_localizer(const Args& args) { return bench_localizer(args); }
int run_bench_loop(const Args& args) { return bench_loop(args); }

}  // namespace lidarloop
