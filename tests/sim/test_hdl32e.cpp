// HDL-32E geometry, timing, noise, motion distortion and determinism, checked against the datasheet
// and against scenes whose geometry is known exactly.
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
    const double expected = config.scan_start_yaw_deg - 360.0 * config.rotation_hz * double(p.t_ns) * 1e-9;
    const double error = std::remainder(std::atan2(p.y, p.x) / kDeg - expected, 360.0);
    ASSERT_NEAR(error, 0.0, 1e-3);
  }
  EXPECT_NEAR(double(cycles.size()), 2170.0, 2.0);
  EXPECT_EQ(*cycles.rbegin() - *cycles.begin() + 1, int64_t(cycles.size()));
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
