// HDL-32E geometry, timing, noise, motion distortion and determinism, checked against the datasheet
// and against scenes whose geometry is known exactly.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "common/units.hpp"
#include "sim/lidar_scanner.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// Velodyne HDL-32E user manual, vertical angles by laser from lowest to highest.
constexpr double kDatasheetElevation[32] = {-30.67, -29.33, -28.00, -26.67, -25.33, -24.00, -22.67, -21.33,
                                            -20.00, -18.67, -17.33, -16.00, -14.67, -13.33, -12.00, -10.67,
                                            -9.33,  -8.00,  -6.67,  -5.33,  -4.00,  -2.67,  -1.33,  0.00,
                                            1.33,   2.67,   4.00,   5.33,   6.67,   8.00,   9.33,   10.67};
constexpr int64_t kFiringNs = 1152, kCycleNs = 46080;

// Ground plus four walls 30 m away: every beam of every firing hits something.
TriangleMesh walled_plane() {
  TriangleMesh mesh = test::flat_ground(40);
  for (float s : {-1.0f, 1.0f}) {
    test::add_wall(mesh, {30.0f * s, 0}, {0.5f, 31}, 20);
    test::add_wall(mesh, {0, 30.0f * s}, {31, 0.5f}, 20);
  }
  return mesh;
}

PointCloud scan_static(const TriangleMesh& mesh, const Hdl32eConfig& config) {
  RayScene scene(mesh);
  const LidarScanner scanner(config, test::materials());
  return scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, 7);
}

int slot_of_ring(int ring) { return ring < 16 ? 2 * ring : 2 * (ring - 16) + 1; }

TEST(Hdl32e, DefaultElevationsAndFiringOrderMatchTheDatasheet) {
  const Hdl32eConfig c;
  for (int ring = 0; ring < 32; ++ring) EXPECT_NEAR(c.elevation_deg[ring], kDatasheetElevation[ring], 0.01);
  // Lower and upper banks alternate: -30.67, -9.33, -29.33, -8.00, ..., -10.67, +10.67.
  for (int ring = 0; ring < 32; ++ring) EXPECT_EQ(c.firing_order[slot_of_ring(ring)], ring);
  EXPECT_EQ(c.cycle_period_ns(), kCycleNs);
  EXPECT_EQ(c.cycles_per_scan(), 2170);
}

TEST(Hdl32e, EveryRingMeasuresItsDatasheetElevation) {
  const PointCloud cloud = scan_static(walled_plane(), test::noiseless_hdl32e());
  std::map<int, int> per_ring;
  for (const auto& p : cloud.points) {
    const double elevation = std::atan2(p.z, std::hypot(p.x, p.y)) / kDeg;
    ASSERT_NEAR(elevation, kDatasheetElevation[p.ring], 0.01) << "ring " << p.ring;
    ++per_ring[p.ring];
  }
  EXPECT_EQ(per_ring.size(), 32u);
  for (const auto& [ring, n] : per_ring) EXPECT_EQ(n, 2170) << "ring " << ring;
}

TEST(Hdl32e, TimesFollowTheFiringSequenceAndTheHeadTurnsClockwise) {
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const PointCloud cloud = scan_static(walled_plane(), config);
  std::set<int64_t> cycles;
  for (const auto& p : cloud.points) {
    // Laser `ring` fires in its own slot, 1.152 us apart, within 46.08 us cycles.
    ASSERT_EQ(int64_t(p.t_ns) % kCycleNs, slot_of_ring(p.ring) * kFiringNs);
    cycles.insert(p.t_ns / kCycleNs);
    // Azimuth: starts at scan_start_yaw and decreases (clockwise seen from above) at 360 deg * 10 Hz.
    // A point is reported at its cycle's azimuth (the encoder reading at the cycle's first firing,
    // on the 0.01 deg grid), as a driver decodes it, not at its own laser's later firing.
    const int64_t cycle_start = p.t_ns - slot_of_ring(p.ring) * kFiringNs;
    const double expected = config.scan_start_yaw_deg - 360.0 * config.rotation_hz * double(cycle_start) * 1e-9;
    const double error = std::remainder(std::atan2(p.y, p.x) / kDeg - expected, 360.0);
    ASSERT_NEAR(error, 0.0, 0.005 + 1e-4);  // half the 0.01 deg step, and float rounding
  }
  EXPECT_NEAR(double(cycles.size()), 2170.0, 2.0);
  EXPECT_EQ(*cycles.rbegin() - *cycles.begin() + 1, int64_t(cycles.size()));
}

// The cloud is what a driver decodes from the blocks the sensor sends: one block per cycle with the
// cycle's azimuth, a return per channel (firing slot) in 2 mm units, and each point at the block's
// azimuth and the channel's calibrated elevation.
TEST(Hdl32e, ReportedPointsAreWhatTheWireCarries) {
  const Hdl32eConfig config = test::noiseless_hdl32e();
  RayScene scene(walled_plane());
  const LidarScanner scanner(config, test::materials());
  Hdl32eRotation wire;
  const PointCloud cloud =
      scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 5'000'000, 7, {}, &wire);
  EXPECT_EQ(wire.start_ns, 5'000'000);
  EXPECT_EQ(wire.cycle_period_ns, kCycleNs);
  ASSERT_EQ(wire.blocks.size(), 2170u);
  EXPECT_EQ(wire.blocks[0].azimuth, 18000);  // scan_start_yaw 180 deg: straight behind
  // 0.1 s per turn: the encoder advances 360 deg * 46.08 us / 0.1 s = 0.165888 deg per cycle,
  // reported to the nearest 0.01 deg: 180.17 deg, and 180 + 165.888 = 345.89 deg 1000 cycles on.
  EXPECT_EQ(wire.blocks[1].azimuth, 18017);
  EXPECT_EQ(wire.blocks[1000].azimuth, 34589);
  size_t next = 0;
  for (size_t cycle = 0; cycle < wire.blocks.size(); ++cycle) {
    const Hdl32eBlock& block = wire.blocks[cycle];
    for (int slot = 0; slot < 32; ++slot) {
      if (block.distance[slot] == 0) continue;
      ASSERT_LT(next, cloud.points.size());
      const LidarPoint& p = cloud.points[next++];
      const int ring = config.firing_order[slot];
      ASSERT_EQ(p.ring, ring);
      ASSERT_EQ(int64_t(p.t_ns), int64_t(cycle) * kCycleNs + slot * kFiringNs);
      ASSERT_EQ(p.intensity, block.intensity[slot]);
      const double v = kDatasheetElevation[ring] * kDeg;
      const Hdl32ePoint q = hdl32e_point(block.azimuth, std::cos(v), std::sin(v), block.distance[slot]);
      ASSERT_NEAR(p.x, q.x, 1e-5);
      ASSERT_NEAR(p.y, q.y, 1e-5);
      ASSERT_NEAR(p.z, q.z, 1e-5);
      ASSERT_NEAR(std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z), block.distance[slot] * 0.002,
                  1e-5);
    }
  }
  EXPECT_EQ(next, cloud.points.size());
}

// A beam fired late in its cycle is cast in its true direction but reported at the cycle's azimuth:
// the last slot (ring 31, 35.7 us = 0.1285 deg of turn after the cycle began; 0.064 deg past the
// cycle's mean firing, which the mount frame absorbs) meets the wall ahead at the range of its true
// direction, so its reported x is W cos(block yaw) / cos(true yaw), not W.
TEST(Hdl32e, ALateBeamIsCastLateButReportedAtItsBlockAzimuth) {
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const PointCloud cloud = scan_static(walled_plane(), config);
  const double late = 31 * 360.0 * config.rotation_hz * double(kFiringNs) * 1e-9 * kDeg;  // rad
  std::vector<double> ahead;  // the wall's distance, from beams straight ahead
  for (const auto& p : cloud.points)
    if (p.ring == 31 && std::abs(std::atan2(p.y, p.x)) < 0.5 * kDeg) ahead.push_back(p.x);
  ASSERT_GT(ahead.size(), 3u);
  std::sort(ahead.begin(), ahead.end());
  const double wall = ahead[ahead.size() / 2];
  int checked = 0;
  for (const auto& p : cloud.points) {
    const double yaw = std::atan2(p.y, p.x);  // the block's, on the 0.01 deg grid
    if (p.ring != 31 || std::abs(yaw) < 25 * kDeg || std::abs(yaw) > 40 * kDeg || p.x < 0) continue;
    // Clockwise: the beam left later, further round; the head sits the mean lag counter-clockwise.
    const double true_yaw = yaw - late + config.mean_firing_lag_deg() * kDeg;
    ASSERT_NEAR(p.x, wall * std::cos(yaw) / std::cos(true_yaw), 0.004) << "yaw " << yaw / kDeg;
    ASSERT_GT(std::abs(p.x - wall), 0.012);  // 0.064 deg at 25-40 deg off the normal: 1.5-2.7 cm
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(Hdl32e, RangeNoiseHasTheConfiguredSigmaAndRangesAreQuantised) {
  Hdl32eConfig config = test::noiseless_hdl32e();
  config.range_noise_m = 0.02;
  const PointCloud cloud = scan_static(walled_plane(), config);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d v(p.x, p.y, p.z);
    const double range = v.norm();
    // 2 mm quantisation: every range is a whole number of steps.
    const double steps = range / config.range_resolution_m;
    ASSERT_NEAR(steps, std::round(steps), 0.02);
    if (std::hypot(p.x, p.y) > 25.0) continue;  // ground hits, whose true range follows from the beam alone
    const double truth = config.mount_xyz.z() / (-v.z() / range);
    sum += range - truth, sum2 += (range - truth) * (range - truth), ++n;
  }
  ASSERT_GT(n, 10000);
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.002);
  EXPECT_NEAR(sigma, 0.02, 0.002);  // within 10 %
}

// Driving at 10 m/s towards a wall: the first and the last firings of one scan look at it from
// positions 1 m apart, so it appears 1 m nearer at the end; without distortion both agree.
double wall_shift(bool motion_distortion) {
  TriangleMesh mesh = test::flat_ground(60);
  test::add_wall(mesh, {25, 0}, {0.5f, 20}, 10);
  Hdl32eConfig config = test::noiseless_hdl32e();
  config.scan_start_yaw_deg = 0;  // the scan starts and ends looking straight ahead
  config.motion_distortion = motion_distortion;
  RayScene scene(mesh);
  const LidarScanner scanner(config, test::materials());
  const PointCloud cloud = scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 10.0, 0), 0, 1);
  const int horizontal_ring = 23;  // 0 deg elevation
  double first = 0, last = 0;
  int64_t t_first = INT64_MAX, t_last = -1;
  for (const auto& p : cloud.points) {
    if (p.ring != horizontal_ring || std::abs(p.y) > 0.5) continue;
    if (p.t_ns < t_first) t_first = p.t_ns, first = p.x;
    if (int64_t(p.t_ns) > t_last) t_last = p.t_ns, last = p.x;
  }
  EXPECT_LT(t_first, 100000);   // within the first 0.1 ms
  EXPECT_GT(t_last, 99000000);  // within the last 1 ms of the 100 ms scan
  return first - last;
}

TEST(Hdl32e, MotionDistortionSkewsAScanTakenWhileDriving) {
  EXPECT_NEAR(wall_shift(true), 1.0, 0.02);
  EXPECT_NEAR(wall_shift(false), 0.0, 0.003);
}

TEST(Hdl32e, SameSeedGivesIdenticalCloudsAtAnyThreadCount) {
  const World world = test::world_from_yaml(R"(
name: det
origin: {lat: 31.0, lon: 121.0}
roads:
  - {name: a, points: [[-100, 0], [100, 0]]}
  - {name: b, points: [[0, -100], [0, 0]]}
poles:
  - {road: a, spacing: 15}
)");
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    RayScene scene(world.mesh, threads);
    const int car = scene.add_prototype(test::flat_ground(2, "vehicle_paint", 1.0f));
    scene.add_actor(car, Eigen::Isometry3d::Identity());
    scene.commit();
    const LidarScanner scanner(Hdl32eConfig{}, test::materials());
    const ActorPoses moving = [](int64_t t, std::vector<Eigen::Isometry3d>& poses) {
      poses[0] = Eigen::Translation3d(10.0 + 12.0 * double(t) * 1e-9, -2.0, 0.0) * Eigen::Isometry3d::Identity();
    };
    return scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 8.0, 0.1), 0, 42, moving);
  };
  const PointCloud one = run(1), two = run(2);
  ASSERT_EQ(one.points.size(), two.points.size());
  ASSERT_GT(one.points.size(), 20000u);
  for (size_t i = 0; i < one.points.size(); ++i) {
    const LidarPoint &a = one.points[i], &b = two.points[i];
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.intensity == b.intensity && a.ring == b.ring &&
                a.t_ns == b.t_ns)
        << "point " << i << " differs";
  }
}

// The mapping drive casts only the lasers that can see the ground: a masked scan is the whole scan's
// points of the lasers cast, to the bit (mixed returns and dropouts on: their draws are by firing).
TEST(Hdl32e, AScanOfSomeLasersIsTheWholeScansPointsOfThoseLasers) {
  Hdl32eConfig config = hdl32e_config_for(Realism::typical);
  config.dropout_probability = 0.05;
  const TriangleMesh mesh = walled_plane();
  RayScene scene(mesh);
  const LidarScanner scanner(config, test::materials());
  const PoseAt pose = constant_twist(Eigen::Isometry3d::Identity(), 0, 8.0, 0.1);
  const uint32_t lasers = 0x0000ffffu | (1u << 20) | (1u << 31);  // the lower half, one mid and the top laser
  const PointCloud whole = scanner.scan(scene, pose, 0, 3), some = scanner.scan(scene, pose, 0, 3, {}, nullptr, lasers);
  std::vector<LidarPoint> expected;
  for (const LidarPoint& p : whole.points)
    if ((lasers >> p.ring) & 1u) expected.push_back(p);
  ASSERT_GT(expected.size(), 20000u);
  ASSERT_LT(expected.size(), whole.points.size());
  ASSERT_EQ(some.points.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    const LidarPoint &a = expected[i], &b = some.points[i];
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.intensity == b.intensity && a.ring == b.ring &&
                a.t_ns == b.t_ns)
        << "point " << i << " differs";
  }
}

TEST(Hdl32e, ConfigOverridesAreValidated) {
  Hdl32eConfig c;
  const YamlReader ok = YamlReader::from_string("rotation_hz: 20\nmount_xyz: [1, 0, 2]\n", "lidar.yaml");
  read_hdl32e_config(ok, ok.root(), c);
  EXPECT_EQ(c.rotation_hz, 20);
  EXPECT_EQ(c.cycles_per_scan(), 1085);
  EXPECT_EQ(c.mount_xyz, Eigen::Vector3d(1, 0, 2));
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {"rotation_hz: 50\n", "lidar.yaml:1:14: rotation_hz = 50 is out of range [5, 20]"},
           {"rpm: 600\n", "lidar.yaml:1:1: unknown key 'rpm'"},
           {"elevation_deg: [1, 2]\n", "lidar.yaml:1:16: elevation_deg must list 32 elevations"},
           {"min_range_m: 5\nmax_range_m: 2\n", "min_range_m must be below max_range_m"}}) {
    const YamlReader bad = YamlReader::from_string(text, "lidar.yaml");
    Hdl32eConfig d;
    try {
      read_hdl32e_config(bad, bad.root(), d);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace lidarloop
