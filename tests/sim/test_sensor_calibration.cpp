// The true sensor mounts against the nominal ones: one draw per run, fixed by the seed, with the
// configured spread over many seeds; the ideal profile draws nothing; the simulation's scanner sits at
// the true mount; the scenario keys.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "sim/sensor_calibration.hpp"
#include "sim/simulation.hpp"
#include "sim/world_assets.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// Every component of a draw, in one vector: LiDAR roll, pitch, yaw, x, y, z, antenna x, y, z.
Eigen::Matrix<double, 9, 1> flat(const MountDraw& d) {
  Eigen::Matrix<double, 9, 1> v;
  v << d.lidar_rpy_rad, d.lidar_xyz_m, d.gps_antenna_m;
  return v;
}

TEST(MountError, TheSeedFixesTheDraw) {
  const MountErrorConfig config;
  EXPECT_EQ(flat(draw_mount_error(config, 7)), flat(draw_mount_error(config, 7)));
  const Eigen::Matrix<double, 9, 1> a = flat(draw_mount_error(config, 7)), b = flat(draw_mount_error(config, 8));
  for (int i = 0; i < 9; ++i) EXPECT_NE(a[i], b[i]) << i;
}

TEST(MountError, SpreadOverManySeedsIsTheConfiguredSigma) {
  // Distinct sigmas per axis, so that a component read from the wrong axis shows.
  MountErrorConfig config;
  config.lidar_rotation_sigma_rad = Eigen::Vector3d(0.1, 0.2, 0.3) * kDeg;
  config.lidar_translation_sigma_m = {0.003, 0.005, 0.007};
  config.gps_antenna_sigma_m = {0.01, 0.02, 0.04};
  Eigen::Matrix<double, 9, 1> sigma;
  sigma << config.lidar_rotation_sigma_rad, config.lidar_translation_sigma_m, config.gps_antenna_sigma_m;
  // 4000 runs: the sample sd is within ~1.1 % (1 sigma) of the true one, the mean within 1.6 % of
  // sigma; the tolerances (the brief's 20 % on the sd, 10 % on the mean) are many sigmas away.
  constexpr int kRuns = 4000;
  Eigen::Matrix<double, 9, 1> sum = Eigen::Matrix<double, 9, 1>::Zero(), sum2 = sum;
  for (int seed = 0; seed < kRuns; ++seed) {
    const Eigen::Matrix<double, 9, 1> v = flat(draw_mount_error(config, uint64_t(seed)));
    sum += v;
    sum2 += v.cwiseProduct(v);
  }
  for (int i = 0; i < 9; ++i) {
    const double mean = sum[i] / kRuns, sd = std::sqrt(sum2[i] / kRuns - mean * mean);
    EXPECT_NEAR(sd, sigma[i], 0.2 * sigma[i]) << "component " << i;
    EXPECT_NEAR(mean, 0.0, 0.1 * sigma[i]) << "component " << i;
    RecordProperty("sd_over_sigma_" + std::to_string(i), std::to_string(sd / sigma[i]));
  }
}

TEST(MountError, IdealDrawsNothingAndTheTrueMountIsTheNominalOne) {
  const MountDraw d = draw_mount_error(mount_error_config_for(Realism::ideal), 123);
  EXPECT_EQ(flat(d), (Eigen::Matrix<double, 9, 1>::Zero()));
  const Hdl32eConfig nominal;
  EXPECT_TRUE(with_true_mount(nominal, d).mount().isApprox(nominal.mount(), 0));
  EXPECT_EQ(with_true_antenna(GpsConfig{}, d).antenna_xyz, GpsConfig{}.antenna_xyz);
}

TEST(MountError, TheTrueMountIsTheNominalMovedByTheDraw) {
  MountDraw d;
  d.lidar_rpy_rad = {0.01, -0.02, 0.03};
  d.lidar_xyz_m = {0.1, -0.2, 0.05};
  d.gps_antenna_m = {0.02, 0.01, -0.03};
  const Hdl32eConfig t = with_true_mount(Hdl32eConfig{}, d);
  EXPECT_TRUE(t.mount_xyz.isApprox(Hdl32eConfig{}.mount_xyz + d.lidar_xyz_m));
  EXPECT_TRUE((t.mount_rpy_deg * kDeg).isApprox(Hdl32eConfig{}.mount_rpy_deg * kDeg + d.lidar_rpy_rad));
  EXPECT_TRUE(with_true_antenna(GpsConfig{}, d).antenna_xyz.isApprox(GpsConfig{}.antenna_xyz + d.gps_antenna_m));
}

constexpr const char* kMinimal = "world: campus\nduration_s: 1\nego: {route: {road: loop}}\n";

TEST(MountError, ProfilesAndScenarioKeys) {
  const Scenario typical = parse_scenario(kMinimal, "s.yaml");
  EXPECT_NEAR(typical.mount_error.lidar_rotation_sigma_rad.x(), 0.1 * kDeg, 1e-12);
  EXPECT_NEAR(typical.mount_error.lidar_translation_sigma_m.z(), 0.003, 1e-12);
  const Scenario harsh = parse_scenario(std::string(kMinimal) + "realism: harsh\n", "s.yaml");
  EXPECT_GT(harsh.mount_error.lidar_rotation_sigma_rad.z(), typical.mount_error.lidar_rotation_sigma_rad.z());
  const Scenario s = parse_scenario(
      std::string(kMinimal) + "mount_error: {lidar_rotation_deg: [0, 0, 0.5], gps_antenna_m: [0.1, 0.1, 0]}\n",
      "s.yaml");
  EXPECT_NEAR(s.mount_error.lidar_rotation_sigma_rad.z(), 0.5 * kDeg, 1e-12);
  EXPECT_EQ(s.mount_error.lidar_rotation_sigma_rad.x(), 0);
  EXPECT_NEAR(s.mount_error.lidar_translation_sigma_m.x(), 0.003, 1e-12);  // not given: the profile's
  EXPECT_EQ(s.mount_error.gps_antenna_sigma_m, Eigen::Vector3d(0.1, 0.1, 0));
  try {
    parse_scenario(std::string(kMinimal) + "mount_error: {lidar_rotation_deg: [0, -1, 0]}\n", "s.yaml");
    FAIL() << "a negative sigma was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:4:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scenario(std::string(kMinimal) + "mount_error: {yaw_deg: 1}\n", "s.yaml"), InputError);
}

// The simulation casts from the true mount: the sensor pose it reports turns from the car's heading
// by the nominal yaw plus the drawn one, and its draw is the seed's.
TEST(MountError, TheSimulationScansFromTheTrueMount) {
  struct Poses : StreamSink {
    std::vector<TruthSample> truth;
    std::vector<std::pair<int64_t, Eigen::Isometry3d>> sensor;
    void on_truth(const TruthSample& s) override { truth.push_back(s); }
    void on_scan(const PointCloud& c, const Eigen::Isometry3d& p) override { sensor.emplace_back(c.stamp_ns, p); }
  };
  const Scenario scenario = parse_scenario(R"(world: campus
duration_s: 1
seed: 42
realism: ideal
ego: {route: {road: loop, lane: right}, start_at: 70, speed: 8, initial_speed: 8}
mount_error: {lidar_rotation_deg: [0, 0, 5.0]}
)",
                                           "s.yaml");
  const WorldDescription description = load_world_description(world_file(scenario.world));
  const World world = build_world(description, test::materials(), test::data_path("assets/actors"));
  Simulation sim(scenario, description, world, test::materials(), test::data_path("assets/actors"), 0);
  const MountDraw expected = draw_mount_error(scenario.mount_error, scenario.seed);
  EXPECT_EQ(flat(sim.mount_draw()), flat(expected));
  ASSERT_GT(std::abs(expected.lidar_rpy_rad.z()), 0.05 * kDeg);  // a draw large enough to see
  Poses rec;
  sim.run(rec);
  ASSERT_FALSE(rec.sensor.empty());
  for (const auto& [stamp, pose] : rec.sensor) {
    // The truth at the stamp (ideal clocks: the stamp is the reference time, on a 10 ms truth sample).
    const int64_t t = stamp;  // a lambda may not capture a structured binding before clang 16
    const auto it =
        std::find_if(rec.truth.begin(), rec.truth.end(), [t](const TruthSample& s) { return s.stamp_ns >= t; });
    if (it == rec.truth.end() || it->stamp_ns != stamp) continue;
    const Eigen::Vector3d forward = pose.rotation() * Eigen::Vector3d::UnitX();
    const double sensor_yaw = std::atan2(forward.y(), forward.x());
    EXPECT_NEAR(wrap_angle(sensor_yaw - it->pose.yaw), expected.lidar_rpy_rad.z(), 0.01 * kDeg);
  }
}

}  // namespace
}  // namespace lidarloop
