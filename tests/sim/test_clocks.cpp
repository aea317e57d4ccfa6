// The LiDAR's and the CAN's stamping clocks against the reference: a known LiDAR clock offset moves a
// wall, placed with the truth pose at the scan's stamp, by v * dt; CAN stamps carry the configured
// offset and jitter while the frames still arrive on the reference clock; the scenario keys.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/can_model.hpp"
#include "sim/clocks.hpp"
#include "sim/simulation.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr int64_t kMs = 1'000'000;

// --- CAN ------------------------------------------------------------------------------------------

TEST(CanClock, StampsCarryTheOffsetAndFramesStillArriveOnTime) {
  CanConfig config;
  const StampClock clock{7 * kMs, 0};
  CanModel can(config, 3, clock);
  for (int k = 1; k <= 100; ++k) {
    const int64_t t = k * can.period_ns();
    can.measure(t, {5, 5, 5, 5}, 0);
    const std::vector<CanFrame> arrived = can.deliver(t + config.latency_ns);  // on the reference clock
    ASSERT_EQ(arrived.size(), 1u);
    EXPECT_EQ(arrived[0].stamp_ns, t + config.latency_ns + clock.offset_ns);
  }
}

TEST(CanClock, JitterHasTheConfiguredSpreadAndNoBias) {
  CanConfig config;
  const StampClock clock{-3 * kMs, 2 * kMs};
  CanModel can(config, 5, clock);
  constexpr int kFrames = 20000;
  double sum = 0, sum2 = 0;
  for (int k = 1; k <= kFrames; ++k) {
    const int64_t t = k * can.period_ns();
    can.measure(t, {5, 5, 5, 5}, 0);
    for (const CanFrame& f : can.deliver(t + config.latency_ns)) {
      const double e = double(f.stamp_ns - (t + config.latency_ns + clock.offset_ns));
      sum += e, sum2 += e * e;
    }
  }
  const double mean = sum / kFrames, sd = std::sqrt(sum2 / kFrames - mean * mean);
  // 20 000 draws: the standard error of the mean is 0.7 % of sigma, of the sd about 0.5 %.
  EXPECT_NEAR(mean, 0.0, 0.03 * double(clock.jitter_ns));
  EXPECT_NEAR(sd, double(clock.jitter_ns), 0.03 * double(clock.jitter_ns));
}

TEST(CanClock, TheReferenceClockLeavesTheFramesAsTheyWere) {
  CanConfig config;
  CanModel plain(config, 9), synchronous(config, 9, StampClock{});
  for (int k = 1; k <= 50; ++k) {
    const int64_t t = k * plain.period_ns();
    plain.measure(t, {3, 3.1, 3, 3.1}, 0.1);
    synchronous.measure(t, {3, 3.1, 3, 3.1}, 0.1);
    const auto a = plain.deliver(t + config.latency_ns), b = synchronous.deliver(t + config.latency_ns);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].stamp_ns, t + config.latency_ns);
      EXPECT_EQ(a[i].stamp_ns, b[i].stamp_ns);
      EXPECT_EQ(a[i].wheel_speed_mps, b[i].wheel_speed_mps);
    }
  }
}

// --- LiDAR: the wall ------------------------------------------------------------------------------

// A straight one-way road with a building beside it: its west face, x = 95, y from 10 to 18, faces
// the ego coming from the west at 10 m/s.
const char* kWallWorld = R"(name: straight
origin: {lat: 31.0, lon: 121.0}
roads:
  - {name: main, points: [[0, 0], [500, 0]], width: 7.0, lanes: 2, one_way: true, marking: dashed, sidewalk_width: 3}
buildings:
  - {centre: [100, 14], size: [10, 8], height: 8}
)";
constexpr double kWallX = 95, kWallYMin = 11, kWallYMax = 17;

struct Recorder : StreamSink {
  std::vector<TruthSample> truth;
  std::vector<PointCloud> scans;
  void on_truth(const TruthSample& s) override { truth.push_back(s); }
  void on_scan(const PointCloud& c, const Eigen::Isometry3d&) override { scans.push_back(c); }
};

Recorder simulate(const std::string& scenario_yaml, const std::string& world_yaml) {
  const Scenario scenario = parse_scenario(scenario_yaml, "test_scenario.yaml");
  const WorldDescription description = parse_world_description(world_yaml, "test_world.yaml");
  const World world = build_world(description, test::materials(), test::data_path("assets/actors"));
  Simulation sim(scenario, description, world, test::materials(), test::data_path("assets/actors"), 0);
  Recorder rec;
  sim.run(rec);
  return rec;
}

// The truth (100 Hz) at any time, linearly between samples: what a scorer or a user with the
// reference clock would use.
Pose2d truth_at(const std::vector<TruthSample>& truth, int64_t t) {
  const auto it =
      std::lower_bound(truth.begin(), truth.end(), t, [](const TruthSample& s, int64_t v) { return s.stamp_ns < v; });
  if (it == truth.begin()) return it->pose;
  if (it == truth.end()) return truth.back().pose;
  const TruthSample &b = *it, &a = *(it - 1);
  const double f = double(t - a.stamp_ns) / double(b.stamp_ns - a.stamp_ns);
  return {a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
          a.pose.yaw + f * wrap_angle(b.pose.yaw - a.pose.yaw)};
}

// The wall's x in each scan, its points placed as a localizer would place them: the nominal mount,
// and the truth pose at the time the scan's stamp and each point's offset give.
std::vector<double> wall_x_per_scan(const Recorder& rec, const Eigen::Isometry3d& mount) {
  std::vector<double> out;
  for (const PointCloud& c : rec.scans) {
    std::vector<double> xs;
    for (const LidarPoint& p : c.points) {
      const Eigen::Vector3d v = mount * Eigen::Vector3d(p.x, p.y, p.z);
      if (v.z() < 1.0) continue;  // above the sidewalk and curbs
      const Pose2d pose = truth_at(rec.truth, c.stamp_ns + int64_t(p.t_ns));
      const Eigen::Vector2d w =
          Eigen::Vector2d(pose.x, pose.y) + Eigen::Rotation2Dd(pose.yaw) * Eigen::Vector2d(v.x(), v.y());
      if (std::abs(w.x() - kWallX) < 2.0 && w.y() > kWallYMin && w.y() < kWallYMax) xs.push_back(w.x());
    }
    if (xs.size() < 20) continue;
    std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
    out.push_back(xs[xs.size() / 2]);
  }
  return out;
}

TEST(LidarClock, AKnownOffsetMovesAWallByVTimesDt) {
  // The ideal profile, so that nothing but the clock differs; same seed, so the scans are the same.
  const std::string scenario = R"(world: straight
duration_s: 3
realism: ideal
ego: {route: {road: main, lane: right}, start_at: 40, speed: 10, initial_speed: 10}
)";
  constexpr double kOffsetS = 0.05;
  const Recorder synchronous = simulate(scenario, kWallWorld);
  const Recorder late = simulate(scenario + "clocks: {lidar_offset_ms: 50}\n", kWallWorld);
  ASSERT_EQ(synchronous.scans.size(), late.scans.size());
  for (size_t k = 0; k < late.scans.size(); ++k)
    EXPECT_EQ(late.scans[k].stamp_ns, synchronous.scans[k].stamp_ns + int64_t(kOffsetS * 1e9));
  const Eigen::Isometry3d mount = Hdl32eConfig{}.mount();
  const std::vector<double> a = wall_x_per_scan(synchronous, mount), b = wall_x_per_scan(late, mount);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(a.size(), 20u);
  double speed = 0;
  for (const TruthSample& s : synchronous.truth) speed += s.speed / double(synchronous.truth.size());
  double shift = 0, wall = 0;
  for (size_t k = 0; k < a.size(); ++k) shift += (b[k] - a[k]) / double(a.size()), wall += a[k] / double(a.size());
  // Synchronous clocks put the wall where it is (the face's median, within the beam's footprint).
  EXPECT_NEAR(wall, kWallX, 0.05);
  // A stamp dt late places every point with the pose dt later: v dt further along the road.
  EXPECT_NEAR(shift, speed * kOffsetS, 0.01);
  RecordProperty("wall_shift_m", std::to_string(shift));
  RecordProperty("v_dt_m", std::to_string(speed * kOffsetS));
}

TEST(LidarClock, JitterIsDrawnPerScanAndFixedBySeed) {
  const std::string scenario = R"(world: straight
duration_s: 2
realism: ideal
ego: {route: {road: main, lane: right}, start_at: 40, speed: 10, initial_speed: 10}
clocks: {lidar_jitter_ms: 5}
)";
  const Recorder a = simulate(scenario, kWallWorld), b = simulate(scenario, kWallWorld);
  const int64_t period = Hdl32eConfig{}.scan_period_ns();
  int moved = 0;
  for (size_t k = 0; k < a.scans.size(); ++k) {
    EXPECT_EQ(a.scans[k].stamp_ns, b.scans[k].stamp_ns);
    const int64_t error = a.scans[k].stamp_ns - int64_t(k) * period;
    EXPECT_LE(std::abs(error), int64_t(3.5 * 5 * kMs));  // the draw's tails stop at 3.46 sigma
    moved += error != 0;
  }
  EXPECT_GT(moved, int(a.scans.size()) / 2);
}

// --- Scenario keys --------------------------------------------------------------------------------

constexpr const char* kMinimal = "world: campus\nduration_s: 1\nego: {route: {road: loop}}\n";

TEST(ClockConfig, ProfilesAndOverrides) {
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + "realism: ideal\n", "s.yaml").clocks.lidar.jitter_ns, 0);
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + "realism: ideal\n", "s.yaml").clocks.can.jitter_ns, 0);
  const Scenario harsh = parse_scenario(std::string(kMinimal) + "realism: harsh\n", "s.yaml");
  EXPECT_EQ(harsh.clocks.lidar.offset_ns, 20 * kMs);
  const Scenario s = parse_scenario(
      std::string(kMinimal) + "realism: ideal\nclocks: {lidar_offset_ms: -12.5, can_jitter_ms: 3}\n", "s.yaml");
  EXPECT_EQ(s.clocks.lidar.offset_ns, -12'500'000);
  EXPECT_EQ(s.clocks.lidar.jitter_ns, 0);
  EXPECT_EQ(s.clocks.can.jitter_ns, 3 * kMs);
  try {
    parse_scenario(std::string(kMinimal) + "clocks: {lidar_ofset_ms: 1}\n", "s.yaml");
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:4:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scenario(std::string(kMinimal) + "clocks: {can_jitter_ms: -1}\n", "s.yaml"), InputError);
}

}  // namespace
}  // namespace lidarloop
