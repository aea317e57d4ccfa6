// The scenario format: a valid scenario loads with its values; every malformed one is rejected with
// its own message at the right line and column.
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "common/units.hpp"
#include "sim/scenario.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

const char* kValid = R"(world: campus
duration_s: 30
seed: 3
ego:
  route: {road: loop, lane: right}
  start_at: 60
  speed: 8
  stops: [{at: 164, duration_s: 2}]
  vehicle: {mass: 2000}
lidar: {rotation_hz: 20}
can: {latency_ms: 20, dropout_probability: 0.01}
gps:
  bias_sigma_m: 1.5
  zones: [{kind: outage, centre: [300, 0], radius: 40, from_s: 5, to_s: 25}]
traffic:
  - {type: bus, path: {road: loop, lane: right, direction: backward}, start_at: 100, speed: 9}
  - {type: pedestrian, path: {crosswalk: 1}, speed: 1.4, depart_s: 3}
  - {type: truck, parked: true, position: [303, 120], yaw_deg: 90}
localizer: {method: icp-obs}
loop: closed
pass: {lateral_rmse_m: 0.1, heading_rmse_deg: 0.3}
)";

TEST(Scenario, AValidScenarioLoadsWithItsValues) {
  const Scenario s = parse_scenario(kValid, "valid.yaml");
  EXPECT_EQ(s.world, "campus");
  EXPECT_EQ(s.duration_ns(), 30'000'000'000);
  EXPECT_EQ(s.seed, 3u);
  EXPECT_EQ(s.ego.route.road, "loop");
  EXPECT_EQ(s.ego.speed, 8);
  ASSERT_EQ(s.ego.stops.size(), 1u);
  EXPECT_EQ(s.ego.vehicle.mass, 2000);
  EXPECT_EQ(s.lidar.rotation_hz, 20);
  EXPECT_EQ(s.can.latency_ns, 20'000'000);
  EXPECT_EQ(s.gps.bias_sigma_m, 1.5);
  ASSERT_EQ(s.gps.zones.size(), 1u);
  EXPECT_EQ(s.gps.zones[0].from_ns, 5'000'000'000);
  ASSERT_EQ(s.traffic.size(), 3u);
  EXPECT_EQ(s.traffic[0].type, ActorType::bus);
  EXPECT_TRUE(s.traffic[0].path.backward);
  EXPECT_EQ(s.traffic[1].path.crosswalk, 1);
  EXPECT_TRUE(s.traffic[2].parked);
  EXPECT_EQ(s.localizer_method, "icp-obs");
  EXPECT_TRUE(s.closed_loop);
  EXPECT_EQ(s.pass.lateral_rmse_m, 0.1);
  EXPECT_FALSE(s.pass.longitudinal_rmse_m.has_value());
}

struct Malformed {
  const char* name;
  std::string yaml;
  const char* location;  // "line:col"
  const char* message;
};

// Replaces the first occurrence of `from` in the valid scenario.
std::string edit(const std::string& from, const std::string& to) {
  std::string s = kValid;
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

// Each case, read as "bad.yaml", must fail at its line and column with its message.
void expect_rejected(const std::vector<Malformed>& cases) {
  for (const auto& c : cases) {
    try {
      parse_scenario(c.yaml, "bad.yaml");
      ADD_FAILURE() << c.name << ": accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(std::string("bad.yaml:") + c.location + ": ", 0), 0u) << c.name << ": " << msg;
      EXPECT_NE(msg.find(c.message), std::string::npos) << c.name << ": " << msg;
    }
  }
}

TEST(Scenario, MalformedScenariosAreRejectedWithTheirOwnMessage) {
  const std::vector<Malformed> cases = {
      {"syntax", edit("seed: 3", "seed: [3"), "4:4", "YAML syntax error"},
      {"unknown top-level key", edit("seed: 3", "sed: 3"), "3:1", "unknown key 'sed'"},
      {"missing world", edit("world: campus\n", ""), "1:1", "missing key 'world'"},
      {"negative duration", edit("duration_s: 30", "duration_s: -5"), "2:13", "duration_s = -5 is out of range"},
      {"duration not a number", edit("duration_s: 30", "duration_s: long"), "2:13", "must be a finite number"},
      {"unknown ego key", edit("  speed: 8\n", "  sped: 8\n"), "7:3", "unknown key 'sped'"},
      {"bad lane", edit("{road: loop, lane: right}", "{road: loop, lane: middle}"), "5:29",
       "lane must be right or left"},
      {"road and waypoints", edit("{road: loop, lane: right}", "{road: loop, waypoints: [[0, 0], [1, 1]]}"), "5:10",
       "exactly one of 'road', 'waypoints', 'crosswalk', 'lanelets', 'opendrive' or 'from' and 'to'"},
      {"stop without duration", edit("{at: 164, duration_s: 2}", "{at: 164}"), "8:11", "missing key 'duration_s'"},
      {"u_turn first", edit("{road: loop, lane: right}", "{lanelets: [u_turn, 7]}"), "5:22",
       "a U-turn must come between two lanelets"},
      {"u_turn last", edit("{road: loop, lane: right}", "{lanelets: [7, u_turn]}"), "5:21",
       "a U-turn must come between two lanelets, not at the end"},
      {"lanelet not an id", edit("{road: loop, lane: right}", "{lanelets: [7, back]}"), "5:25",
       "a lanelet id (or u_turn)"},
      {"vehicle key", edit("{mass: 2000}", "{weight: 2000}"), "9:13", "unknown key 'weight'"},
      {"lidar out of range", edit("{rotation_hz: 20}", "{rotation_hz: 50}"), "10:22",
       "rotation_hz = 50 is out of range"},
      {"can type", edit("latency_ms: 20", "latency_ms: soon"), "11:19", "latency_ms must be a finite number"},
      {"zone kind", edit("kind: outage", "kind: fog"), "14:18", "zone kind must be outage or multipath"},
      {"zone times reversed", edit("from_s: 5, to_s: 25", "from_s: 25, to_s: 5"), "14:11", "to_s must be after"},
      {"unknown actor type", edit("{type: bus,", "{type: tank,"), "16:12", "unknown actor type 'tank'"},
      {"moving actor without speed", edit("start_at: 100, speed: 9", "start_at: 100"), "16:5", "missing key 'speed'"},
      {"parked actor with a path", edit("parked: true,", "parked: true, path: {road: loop},"), "18:39",
       "path makes no sense for a parked actor"},
      {"unknown method", edit("{method: icp-obs}", "{method: slam}"), "19:21", "unknown localizer method 'slam'"},
      {"bad loop", edit("loop: closed", "loop: maybe"), "20:7", "loop must be open or closed"},
      {"unknown threshold", edit("heading_rmse_deg", "heading_rms_deg"), "21:29", "unknown key 'heading_rms_deg'"},
      {"coverage above 1", edit("heading_rmse_deg: 0.3", "min_coverage: 1.5"), "21:43",
       "min_coverage = 1.5 is out of range"},
      {"duplicate key", edit("seed: 3\n", "seed: 3\nseed: 4\n"), "4:1", "key 'seed' appears twice"},
      {"unknown realism", edit("seed: 3\n", "seed: 3\nrealism: gritty\n"), "4:10",
       "realism must be ideal, typical or harsh, got 'gritty'"},
  };
  expect_rejected(cases);
}

TEST(Scenario, RealismIsTypicalUnlessTheScenarioOrTheCommandSaysOtherwise) {
  EXPECT_EQ(parse_scenario(kValid, "valid.yaml").realism, Realism::typical);
  const std::string harsh = edit("seed: 3\n", "seed: 3\nrealism: harsh\n");
  EXPECT_EQ(parse_scenario(harsh, "harsh.yaml").realism, Realism::harsh);
  EXPECT_EQ(parse_scenario(harsh, "harsh.yaml", {}, Realism::ideal).realism, Realism::ideal);
}

TEST(Scenario, RealismOverridesListTheKnobSectionsScalarsInFileOrder) {
  const Scenario s = parse_scenario(kValid, "valid.yaml");
  const std::vector<std::string> expected = {"lidar.rotation_hz = 20",         "can.latency_ms = 20",
                                             "can.dropout_probability = 0.01", "gps.bias_sigma_m = 1.5",
                                             "gps.zones[0].kind = outage",     "gps.zones[0].centre[0] = 300",
                                             "gps.zones[0].centre[1] = 0",     "gps.zones[0].radius = 40",
                                             "gps.zones[0].from_s = 5",        "gps.zones[0].to_s = 25"};
  EXPECT_EQ(realism_overrides(s), expected);  // ego, traffic, localizer and pass are not realism knobs
}

// `faults`: kidnaps of the localizer's belief or of the car, at a time within the run, strictly read like the rest.
TEST(Scenario, FaultsAreKidnapsWithinTheRun) {
  const std::string base = "world: campus\nduration_s: 20\nego: {route: {road: loop}}\n";
  const Scenario s = parse_scenario(base +
                                        "faults:\n"
                                        "  - {kind: kidnap, at_s: 12.0, offset: [3.0, -2.0], yaw_deg: 2.0}\n"
                                        "  - {kind: kidnap, at_s: 5, offset: [0, 1]}\n"
                                        "  - {kind: kidnap, at_s: 7, offset: [2, 1], moves: car}\n"
                                        "  - {kind: kidnap, at_s: 9, offset: [2, 1], moves: belief}\n",
                                    "faults.yaml");
  ASSERT_EQ(s.kidnaps.size(), 4u);
  EXPECT_EQ(s.kidnaps[0].moves, KidnapMoves::belief);  // by default
  EXPECT_EQ(s.kidnaps[2].moves, KidnapMoves::car);
  EXPECT_EQ(s.kidnaps[3].moves, KidnapMoves::belief);
  EXPECT_EQ(s.kidnaps[0].at_s, 12.0);
  EXPECT_EQ(s.kidnaps[0].offset_m, Eigen::Vector2d(3.0, -2.0));
  EXPECT_NEAR(s.kidnaps[0].yaw_rad, 2.0 * kDeg, 1e-15);
  EXPECT_EQ(s.kidnaps[1].at_s, 5.0);
  EXPECT_EQ(s.kidnaps[1].yaw_rad, 0.0);  // no yaw_deg: a pure shift
  EXPECT_TRUE(parse_scenario(base, "none.yaml").kidnaps.empty());

  const std::vector<Malformed> cases = {
      {"not a list", base + "faults: {kind: kidnap}\n", "4:9", "faults must be a list"},
      {"unknown kind", base + "faults: [{kind: jump, at_s: 1, offset: [1, 0]}]\n", "4:17",
       "unknown fault kind 'jump' (expected kidnap"},
      {"no kind", base + "faults: [{at_s: 1, offset: [1, 0]}]\n", "4:10", "missing key 'kind'"},
      {"after the end", base + "faults: [{kind: kidnap, at_s: 21, offset: [1, 0]}]\n", "4:31",
       "at_s = 21 is out of range [0, 20]"},
      {"before the start", base + "faults: [{kind: kidnap, at_s: -1, offset: [1, 0]}]\n", "4:31",
       "at_s = -1 is out of range"},
      {"no offset", base + "faults: [{kind: kidnap, at_s: 1}]\n", "4:10", "missing key 'offset'"},
      {"offset of three", base + "faults: [{kind: kidnap, at_s: 1, offset: [1, 0, 0]}]\n", "4:42",
       "offset must be [x, y]"},
      {"offset not finite", base + "faults: [{kind: kidnap, at_s: 1, offset: [.nan, 0]}]\n", "4:43",
       "offset must be a finite number"},
      {"yaw out of range", base + "faults: [{kind: kidnap, at_s: 1, offset: [1, 0], yaw_deg: 270}]\n", "4:59",
       "yaw_deg = 270 is out of range"},
      {"unknown key", base + "faults: [{kind: kidnap, at_s: 1, offset: [1, 0], heading: 2}]\n", "4:50",
       "unknown key 'heading'"},
      {"moves neither", base + "faults: [{kind: kidnap, at_s: 1, offset: [1, 0], moves: world}]\n", "4:57",
       "moves must be belief or car, got 'world'"},
  };
  expect_rejected(cases);
}

class ScenarioOnCampus : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    description_ = new WorldDescription(load_world_description(test::data_path("maps/campus/world.yaml")));
    world_ = new World(build_world(*description_, test::materials(), test::data_path("assets/actors")));
  }
  static void TearDownTestSuite() {
    delete world_;
    delete description_;
  }
  static void expect_resolve_error(const std::string& yaml, const std::string& location, const std::string& message) {
    try {
      resolve_scenario(parse_scenario(yaml, "bad.yaml"), *description_, *world_);
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("bad.yaml:" + location + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(message), std::string::npos) << msg;
    }
  }
  static WorldDescription* description_;
  static World* world_;
};
WorldDescription* ScenarioOnCampus::description_ = nullptr;
World* ScenarioOnCampus::world_ = nullptr;

TEST_F(ScenarioOnCampus, ValidScenarioResolvesOnTheRoads) {
  const ResolvedScenario r = resolve_scenario(parse_scenario(kValid, "valid.yaml"), *description_, *world_);
  EXPECT_TRUE(r.ego_route.closed);
  EXPECT_GT(r.ego_route.length, 1800.0);
  ASSERT_EQ(r.actors.size(), 3u);
  EXPECT_EQ(r.actors[1].name, "pedestrian_1");
}

TEST_F(ScenarioOnCampus, PathsOffTheRoadNetworkAreRejected) {
  expect_resolve_error(edit("{road: loop, lane: right}", "{waypoints: [[50, 0], [150, 100]]}"), "5:10",
                       "the ego's route leaves the road network");
  expect_resolve_error(edit("{road: loop, lane: right}", "{road: highway}"), "5:10", "unknown road 'highway'");
  expect_resolve_error(edit("{road: loop, lane: right, direction: backward}", "{road: loop, offset: 9}"), "16:23",
                       "the actor's path leaves the road network");
  expect_resolve_error(edit("{crosswalk: 1}", "{crosswalk: 40}"), "17:30", "there is no crosswalk 40");
  expect_resolve_error(edit("position: [303, 120]", "position: [5000, 120]"), "18:5", "outside the world");
}

// `reference`: the profile's RTK reference (none under ideal), each knob over it, strictly read; and
// `pass.against`, which needs one.
TEST(Scenario, ReferenceIsTheProfilesUnlessTheScenarioSetsIt) {
  const std::string base = "world: campus\nduration_s: 20\nego: {route: {road: loop}}\n";
  const Scenario typical = parse_scenario(base, "typical.yaml");
  EXPECT_EQ(typical.reference.kind, ReferenceConfig::Kind::rtk);
  EXPECT_EQ(typical.reference.sigma_xy_m, kRtkReferenceSigma_m);
  EXPECT_DOUBLE_EQ(typical.reference.heading_sigma_rad, kRtkReferenceHeadingSigma_deg * kDeg);
  EXPECT_EQ(typical.reference.correlation_s, kRtkReferenceCorrelation_s);
  EXPECT_FALSE(typical.pass.against_reference);
  EXPECT_EQ(parse_scenario(base, "harsh.yaml", {}, Realism::harsh).reference.kind, ReferenceConfig::Kind::rtk);
  EXPECT_EQ(parse_scenario(base, "ideal.yaml", {}, Realism::ideal).reference.kind, ReferenceConfig::Kind::none);

  const Scenario set = parse_scenario(base +
                                          "reference: {kind: rtk, sigma_xy_m: 0.02, heading_sigma_deg: 0.05, "
                                          "correlation_s: 60}\npass: {against: reference}\n",
                                      "set.yaml", {}, Realism::ideal);
  EXPECT_EQ(set.reference.kind, ReferenceConfig::Kind::rtk);
  EXPECT_EQ(set.reference.sigma_xy_m, 0.02);
  EXPECT_DOUBLE_EQ(set.reference.heading_sigma_rad, 0.05 * kDeg);
  EXPECT_EQ(set.reference.correlation_s, 60);
  EXPECT_TRUE(set.pass.against_reference);
  const std::vector<std::string> overrides = {"reference.kind = rtk", "reference.sigma_xy_m = 0.02",
                                              "reference.heading_sigma_deg = 0.05", "reference.correlation_s = 60"};
  EXPECT_EQ(realism_overrides(set), overrides);
  EXPECT_EQ(parse_scenario(base + "reference: {kind: none}\n", "none.yaml").reference.kind,
            ReferenceConfig::Kind::none);

  const std::vector<Malformed> cases = {
      {"unknown reference key", base + "reference: {sigma_m: 0.03}\n", "4:13", "unknown key 'sigma_m'"},
      {"unknown reference kind", base + "reference: {kind: gps}\n", "4:19", "reference kind must be none or rtk"},
      {"negative sigma", base + "reference: {sigma_xy_m: -0.01}\n", "4:25", "sigma_xy_m = -0.01 is out of range"},
      {"heading not a number", base + "reference: {heading_sigma_deg: small}\n", "4:32",
       "heading_sigma_deg must be a finite number"},
      {"zero correlation", base + "reference: {correlation_s: 0}\n", "4:28", "correlation_s = 0 is out of range"},
      {"a knob without a reference", base + "reference: {kind: none, sigma_xy_m: 0.03}\n", "4:37",
       "sigma_xy_m needs a reference: kind is none"},
      {"not a mapping", base + "reference: rtk\n", "4:12", "reference"},
      {"bad against", base + "pass: {against: gps}\n", "4:17", "against must be truth or reference"},
      {"against without a reference", base + "reference: {kind: none}\npass: {against: reference}\n", "5:17",
       "pass against the reference, but the scenario has none"},
  };
  expect_rejected(cases);
}

// Thresholds given apart from a scenario (lidarloop score): a file with a `pass:` mapping and
// KEY=VALUE arguments, each over what came before and as strictly checked as a scenario's.
TEST(Scenario, PassThresholdsFromAFileAndFromArguments) {
  const Scenario s = parse_scenario(kValid, "valid.yaml");
  EXPECT_FALSE(s.pass.min_coverage.has_value());
  const std::string path = testing::TempDir() + "pass.yaml";
  std::ofstream(path) << "pass: {min_coverage: 0.9, lateral_rmse_m: 0.2}\n";
  PassThresholds p = load_pass_file(path, s.pass);
  EXPECT_EQ(p.min_coverage, 0.9);
  EXPECT_EQ(p.lateral_rmse_m, 0.2);    // replaced
  EXPECT_EQ(p.heading_rmse_deg, 0.3);  // kept from the scenario
  p = parse_pass_assignment("settle_s=1.5", "--threshold", p);
  EXPECT_EQ(p.settle_s, 1.5);
  EXPECT_EQ(p.min_coverage, 0.9);

  auto fails = [&](const std::function<void()>& f, const std::string& expected) {
    try {
      f();
      ADD_FAILURE() << expected << ": accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  fails([&] { parse_pass_assignment("lateral_rmse_m", "--threshold", {}); }, "--threshold: expected KEY=VALUE");
  fails([&] { parse_pass_assignment("lateral=1", "--threshold", {}); }, "unknown key 'lateral'");
  fails([&] { parse_pass_assignment("min_coverage=2", "--threshold", {}); }, "min_coverage = 2 is out of range");
  fails([&] { parse_pass_assignment("settle_s=soon", "--threshold", {}); }, "settle_s must be a finite number");
  std::ofstream(path) << "pass: {min_coverage: 0.9}\nseed: 3\n";
  fails([&] { load_pass_file(path, {}); }, "pass.yaml:2:1: unknown key 'seed'");
  std::ofstream(path) << "thresholds: {}\n";
  fails([&] { load_pass_file(path, {}); }, "missing key 'pass'");
}

}  // namespace
}  // namespace lidarloop
