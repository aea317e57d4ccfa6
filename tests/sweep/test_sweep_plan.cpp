// Sweep files: expressions, the grid's expansion, derived values, copies, shards and the errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "common/input_error.hpp"
#include "sweep/sweep_expression.hpp"
#include "sweep/sweep_plan.hpp"
#include "sweep/sweep_report.hpp"

using namespace lidarloop;

namespace {

namespace fs = std::filesystem;

const char* const kBase = R"(world: campus
duration_s: 10
seed: 1
ego:
  route: {road: loop, lane: right, offset: -0.2}
  start_at: 80
  speed: 10.0
traffic:
  - {type: bus, path: {road: loop, lane: right, offset: -2.6}, start_at: 84, speed: 10.0, waits: [{at: 234, duration_s: 100}]}
  - {type: car, path: {road: loop, lane: right}, start_at: 120, speed: 10.0}
localizer: {method: proposed}
pass: {lateral_rmse_m: 0.1}
)";

// A sweep file (and the base scenario beside it) in a fresh folder; returns the sweep's path.
std::string write_sweep(const std::string& name, const std::string& sweep) {
  const fs::path dir = fs::temp_directory_path() / ("lidarloop_sweep_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "base.yaml") << kBase;
  std::ofstream(dir / "sweep.yaml") << sweep;
  return (dir / "sweep.yaml").string();
}

std::string error_of(const std::string& name, const std::string& sweep) {
  try {
    expand_sweep(load_sweep(write_sweep(name, sweep)));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

YAML::Node scenario_of(const SweepRun& run) { return YAML::Load(run.scenario_text); }

}  // namespace

TEST(SweepExpression, HonoursPrecedenceParenthesesAndUnaryMinus) {
  const std::map<std::string, double> names = {{"side", -1}, {"gap_m", 0.5}};
  EXPECT_DOUBLE_EQ(evaluate_expression("side * (4.5 - gap_m - 1.28)", names), -2.72);
  EXPECT_DOUBLE_EQ(evaluate_expression("84 + 10 * 5 / 2", names), 109);
  EXPECT_DOUBLE_EQ(evaluate_expression("-(1 - 3) * -2", names), -4);
  EXPECT_DOUBLE_EQ(evaluate_expression(" 2.5e1 ", names), 25);
}

TEST(SweepExpression, RejectsUnknownNamesSyntaxErrorsAndDivisionByZero) {
  const std::map<std::string, double> names = {{"gap_m", 0.5}};
  for (const char* bad : {"gap + 1", "1 +", "(1 + 2", "1 2", "1 / (gap_m - 0.5)", "gap_m ^ 2", ""})
    EXPECT_THROW(evaluate_expression(bad, names), InputError) << bad;
}

TEST(SweepPlan, ExpandsTheGridFirstAxisSlowestThenSeeds) {
  const SweepSpec spec = load_sweep(write_sweep("grid", R"(scenario: base.yaml
seeds: 4-5
methods: [proposed, icp]
grid:
  - {name: side, levels: {right: -1, left: 1}}
  - {name: gap_m, range: {from: 0.5, to: 1.5, step: 0.5}}
set:
  traffic[0].path.offset: side * (4.5 - gap_m - 1.28)
)"));
  const std::vector<SweepRun> runs = expand_sweep(spec);
  ASSERT_EQ(runs.size(), 2u * 3u * 2u);  // open loop: both methods on one drive
  EXPECT_EQ(runs[0].id, "0000");
  EXPECT_EQ(runs[11].id, "0011");
  EXPECT_EQ(runs[0].methods, (std::vector<std::string>{"proposed", "icp"}));
  // Run 7: side = left (the second half), gap_m = 1.0 (the second level), seed 5.
  EXPECT_EQ(runs[7].level, (std::vector<size_t>{1, 0}));
  EXPECT_EQ(runs[9].level, (std::vector<size_t>{1, 1}));
  EXPECT_EQ(runs[9].seed, 5u);
  const YAML::Node s = scenario_of(runs[9]);
  EXPECT_DOUBLE_EQ(s["traffic"][0]["path"]["offset"].as<double>(), 4.5 - 1.0 - 1.28);
  EXPECT_EQ(s["seed"].as<int>(), 5);
  EXPECT_DOUBLE_EQ(scenario_of(runs[0])["traffic"][0]["path"]["offset"].as<double>(), -(4.5 - 0.5 - 1.28));
  // Everything else is the base's.
  EXPECT_EQ(s["traffic"][1]["start_at"].as<double>(), 120);
  EXPECT_EQ(s["pass"]["lateral_rmse_m"].as<double>(), 0.1);
}

TEST(SweepPlan, ZipsSetSeveralPathsInLockstepAndCopiesRepeatAnEntry) {
  const SweepSpec spec = load_sweep(write_sweep("zip", R"(scenario: base.yaml
grid:
  - name: lane
    zip:
      traffic[1].path.lane: [right, left]
      traffic[1].speed: [10, 7]
  - {name: coaches, values: [0, 1, 3]}
copies:
  of: traffic[0]
  count: coaches
  shift:
    start_at: 15
    waits[0].at: 15
)"));
  const std::vector<SweepRun> runs = expand_sweep(spec);
  ASSERT_EQ(runs.size(), 6u);
  // lane = left, coaches = 3: the coach, two copies 15 and 30 m ahead, then the car.
  const YAML::Node s = scenario_of(runs[5]);
  ASSERT_EQ(s["traffic"].size(), 4u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s["traffic"][k]["type"].as<std::string>(), "bus");
    EXPECT_DOUBLE_EQ(s["traffic"][k]["start_at"].as<double>(), 84 + 15 * k);
    EXPECT_DOUBLE_EQ(s["traffic"][k]["waits"][0]["at"].as<double>(), 234 + 15 * k);
  }
  EXPECT_EQ(s["traffic"][3]["path"]["lane"].as<std::string>(), "left");
  EXPECT_EQ(s["traffic"][3]["speed"].as<double>(), 7);
  // coaches = 0 removes the coach.
  const YAML::Node none = scenario_of(runs[3]);
  ASSERT_EQ(none["traffic"].size(), 1u);
  EXPECT_EQ(none["traffic"][0]["type"].as<std::string>(), "car");
  EXPECT_FALSE(spec.axes[0].numeric());
  EXPECT_TRUE(spec.axes[1].numeric());
}

TEST(SweepPlan, ClosedLoopGivesEachMethodItsOwnRun) {
  const std::string path = write_sweep("closed", "scenario: base.yaml\nmethods: [proposed, icp]\n");
  std::ofstream(fs::path(path).parent_path() / "base.yaml") << kBase << "loop: closed\n";
  const std::vector<SweepRun> runs = expand_sweep(load_sweep(path));
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].methods, std::vector<std::string>{"proposed"});
  EXPECT_EQ(runs[1].methods, std::vector<std::string>{"icp"});
}

TEST(SweepPlan, ErrorsNameTheLineAndTheProblem) {
  auto has = [](const std::string& error, const std::string& part) { return error.find(part) != std::string::npos; };
  std::string e = error_of("unknown_key", "scenario: base.yaml\nseeds: 1-2\ngird: []\n");
  EXPECT_TRUE(has(e, "sweep.yaml:3:1: unknown key 'gird'")) << e;
  e = error_of("bad_index", "scenario: base.yaml\ngrid:\n  - path: traffic[5].speed\n    values: [1]\n");
  EXPECT_TRUE(has(e, "sweep.yaml:3:11:") && has(e, "'traffic' has 2 entries, no [5]")) << e;
  e = error_of("zip_length",
               "scenario: base.yaml\ngrid:\n  - name: z\n    zip:\n      seed: [1, 2]\n      duration_s: [3]\n");
  EXPECT_TRUE(has(e, "sweep.yaml:6:19: zip 'duration_s' has 1 values, the first list 2")) << e;
  e = error_of("two_kinds",
               "scenario: base.yaml\ngrid:\n  - {name: a, values: [1], range: {from: 0, to: 1, step: 1}}\n");
  EXPECT_TRUE(has(e, "give exactly one of values, levels, range or zip")) << e;
  e = error_of("metric", "scenario: base.yaml\nmetrics: [lateral_rmse]\n");
  EXPECT_TRUE(has(e, "sweep.yaml:2:11: unknown metric 'lateral_rmse'")) << e;
  e = error_of("method", "scenario: base.yaml\nmethods: [proposed, magic]\n");
  EXPECT_TRUE(has(e, "sweep.yaml:2:21:") && has(e, "magic")) << e;
  e = error_of("missing_base", "scenario: nowhere.yaml\n");
  EXPECT_TRUE(has(e, "nowhere.yaml")) << e;
  // A level that makes a scenario the scenario's own check refuses names the run and the level.
  e = error_of("bad_level", "scenario: base.yaml\ngrid:\n  - {path: ego.speed, values: [10, -5]}\n");
  EXPECT_TRUE(has(e, "run 0001 (ego.speed = -5, seed 1)")) << e;
}

TEST(SweepPlan, ShardsPartitionTheRunsTheSameWayEverywhere) {
  for (size_t count : {1u, 3u, 4u, 7u}) {
    std::multiset<size_t> seen;
    for (size_t i = 0; i < count; ++i) {
      const Shard s = parse_shard(std::to_string(i) + "/" + std::to_string(count));
      for (size_t run = 0; run < 50; ++run)
        if (s.contains(run)) seen.insert(run);
    }
    ASSERT_EQ(seen.size(), 50u);
    for (size_t run = 0; run < 50; ++run) EXPECT_EQ(seen.count(run), 1u);
  }
  for (const char* bad : {"4/4", "1/0", "a/b", "1", "-1/2", "1/2/3"}) EXPECT_THROW(parse_shard(bad), InputError) << bad;
}

TEST(SweepReport, OneRowPerRunAndMethodWithWhatIsKnown) {
  SweepPlan plan;
  plan.sweep_file = "s.yaml";
  plan.axes = {SweepAxis{"gap_m", "", {{"0.5", 0.5, {}}, {"2", 2.0, {}}}}};
  plan.methods = {"proposed"};
  plan.metrics = {"lateral_rmse_m"};
  for (size_t k = 0; k < 2; ++k) plan.runs.push_back({k, "000" + std::to_string(k), {k}, 7, {"proposed"}, ""});
  std::vector<RunResult> results(2);
  results[0].end.status = RunStatus::done;
  results[0].methods["proposed"] = {true, {{"lateral_rmse_m", 0.0125}, {"curb_hidden_fraction", 0.25}}};
  results[1].end.status = RunStatus::timeout;
  EXPECT_EQ(sweep_csv(plan, results),
            "run,gap_m,seed,method,status,pass,lateral_rmse_m,curb_hidden_fraction\n"
            "0000,0.5,7,proposed,done,true,0.0125,0.25\n"
            "0001,2,7,proposed,timeout,,,\n");
  // The plan survives its JSON.
  const std::string path = (fs::temp_directory_path() / "lidarloop_sweep_plan.json").string();
  std::ofstream(path) << sweep_plan_json(plan);
  const SweepPlan back = read_sweep_plan(path);
  EXPECT_EQ(sweep_csv(back, results), sweep_csv(plan, results));
}

TEST(SweepReport, FailureRateCountsMissedThresholdsAndUnfinishedRunsNotMissingOnes) {
  SweepPlan plan;
  plan.sweep_file = "s.yaml";
  plan.axes = {SweepAxis{"gap_m", "", {{"0.5", 0.5, {}}}}};
  plan.methods = {"proposed"};
  plan.metrics = {"lateral_rmse_m"};
  for (size_t k = 0; k < 4; ++k) plan.runs.push_back({k, "000" + std::to_string(k), {0}, k, {"proposed"}, ""});
  std::vector<RunResult> results(4);
  results[0].end.status = RunStatus::done;
  results[0].methods["proposed"] = {true, {{"lateral_rmse_m", 0.01}}};
  results[1].end.status = RunStatus::done;
  results[1].methods["proposed"] = {false, {{"lateral_rmse_m", 0.03}}};  // missed a threshold
  results[2].end.status = RunStatus::crashed;
  // results[3]: missing (a shard not run yet)
  const fs::path dir = fs::temp_directory_path() / "lidarloop_sweep_report";
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_sweep_report(dir.string(), plan, results);
  std::ifstream in(dir / "sweep.md");
  const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Three runs ended, two failed; the mean and spread are over the two with metrics.
  EXPECT_NE(md.find("| 0.5 | 3 | 66.7 % | 0.02 ± 0.014 |"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(dir / "plots" / "lateral_rmse_m_vs_gap_m.png"));
  EXPECT_TRUE(fs::exists(dir / "plots" / "failure_rate_vs_gap_m.png"));
}
