// Weather: a wet road's darker asphalt and paint, puddles that return nothing, rain's spurious near
// returns, spray behind moving vehicles; the profiles and the scenario keys.
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "sim/lidar_scanner.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr uint64_t kSeed = 7;

PointCloud scan_static(const TriangleMesh& mesh, const WeatherConfig& weather,
                       const Hdl32eConfig& config = test::noiseless_hdl32e()) {
  RayScene scene(mesh);
  const LidarScanner scanner(config, test::materials(), weather);
  return scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, kSeed);
}

// Asphalt with a 2 m wide paint band at x in [4, 6] across the whole width.
TriangleMesh painted_road() {
  TriangleMesh mesh = test::flat_ground(40);
  add_flat_quad(mesh,
                {Eigen::Vector2f(4, -40), Eigen::Vector2f(6, -40), Eigen::Vector2f(6, 40), Eigen::Vector2f(4, 40)},
                0.003f, test::materials().id("lane_paint", "test"));
  return mesh;
}

Eigen::Vector3d world_point(const LidarPoint& p, const Hdl32eConfig& c) {
  return c.mount_xyz + test::fired_point(p, c);
}

TEST(Weather, WetPaintAndAsphaltReadTheConfiguredFractionOfTheirDryIntensity) {
  WeatherConfig wet;
  wet.wet = true;
  const Hdl32eConfig config = test::noiseless_hdl32e();
  std::map<std::pair<int, uint32_t>, int> dry_intensity;
  for (const auto& p : scan_static(painted_road(), {}).points) dry_intensity[{p.ring, p.t_ns}] = p.intensity;
  double paint_dry = 0, paint_wet = 0, asphalt_dry = 0, asphalt_wet = 0;
  int n_paint = 0, n_asphalt = 0;
  for (const auto& p : scan_static(painted_road(), wet).points) {
    const Eigen::Vector3d w = world_point(p, config);
    const auto d = dry_intensity.find({p.ring, p.t_ns});
    ASSERT_NE(d, dry_intensity.end());
    if (w.x() > 4.1 && w.x() < 5.9 && std::abs(w.y()) < 8)
      paint_dry += d->second, paint_wet += p.intensity, ++n_paint;
    else if (w.norm() < 10 && (w.x() < 3.5 || w.x() > 6.5))
      asphalt_dry += d->second, asphalt_wet += p.intensity, ++n_asphalt;
  }
  ASSERT_GT(n_paint, 200);
  ASSERT_GT(n_asphalt, 1000);
  // Intensities are whole counts: a ratio of sums is good to about 0.5 / mean count.
  EXPECT_NEAR(paint_wet / paint_dry, wet.wet_marking_factor, 0.02);
  EXPECT_NEAR(asphalt_wet / asphalt_dry, wet.wet_road_factor, 0.05);
}

TEST(Weather, PuddlesCoverTheConfiguredShareOfTheGround) {
  WeatherConfig w;
  w.puddle_fraction = 0.2;
  int in = 0, n = 0;
  for (double x = -100; x < 100; x += 0.13)
    for (double y = -100; y < 100; y += 0.17) in += in_puddle(w, kSeed, x, y), ++n;
  EXPECT_NEAR(double(in) / n, 0.2, 0.02);
  EXPECT_FALSE(in_puddle(WeatherConfig{}, kSeed, 1, 1));
}

TEST(Weather, PuddlesReturnNothingWhereTheyAreAndTheRestIsUnchanged) {
  WeatherConfig w;
  w.puddle_fraction = 0.2;
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const PointCloud dry = scan_static(test::flat_ground(40), {}), puddled = scan_static(test::flat_ground(40), w);
  // A point is placed from its measured (2 mm quantised) range: within 1 cm of a puddle's rim it may
  // fall either side. 1: clearly in a puddle, 0: clearly out, -1: at a rim.
  auto where = [&](const LidarPoint& p) {
    const Eigen::Vector3d g = world_point(p, config);
    int in = 0;
    for (const auto& [dx, dy] : {std::pair{0.01, 0.0}, {-0.01, 0.0}, {0.0, 0.01}, {0.0, -0.01}})
      in += in_puddle(w, kSeed, g.x() + dx, g.y() + dy);
    return in == 4 ? 1 : in == 0 ? 0 : -1;
  };
  size_t in_puddles = 0, at_rims = 0;
  for (const auto& p : dry.points) in_puddles += where(p) == 1, at_rims += where(p) == -1;
  for (const auto& p : puddled.points) ASSERT_NE(where(p), 1) << world_point(p, config).transpose();
  EXPECT_GT(in_puddles, 2000u);
  EXPECT_LE(puddled.points.size(), dry.points.size() - in_puddles);
  EXPECT_GE(puddled.points.size(), dry.points.size() - in_puddles - at_rims);
  // A sidewalk is no carriageway: puddles leave it alone.
  EXPECT_EQ(scan_static(test::flat_ground(40, "sidewalk"), w).points.size(),
            scan_static(test::flat_ground(40, "sidewalk"), {}).points.size());
}

TEST(Weather, RainGivesSpuriousNearReturnsAtTheConfiguredRate) {
  // Nothing to hit but a small plate far away: every return is a rain drop.
  TriangleMesh mesh = test::flat_ground(1, "building", -90);
  WeatherConfig w;
  w.rain_rate_mm_h = 50;
  w.rain_clutter_per_mm_h = 2e-4;  // 1 % of firings
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const PointCloud cloud = scan_static(mesh, w, config);
  const double firings = 2170.0 * 32;
  // Binomial: sigma = sqrt(0.01 * 694) = 26 of 694 expected.
  EXPECT_NEAR(double(cloud.points.size()), 0.01 * firings, 100);
  double mean = 0;
  for (const auto& p : cloud.points) {
    const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    EXPECT_GE(r, config.min_range_m);
    EXPECT_LE(p.intensity, w.clutter_intensity);
    mean += r - config.min_range_m;
  }
  EXPECT_NEAR(mean / double(cloud.points.size()), w.rain_clutter_range_m, 0.3);  // exponential, sigma/sqrt(n)
  EXPECT_EQ(scan_static(mesh, {}, config).points.size(), 0u);
}

TEST(Weather, SprayTrailsAMovingCarOnAWetRoad) {
  // A car-sized box driving away at 15 m/s, 10 m ahead on a road: spray fills the space behind it.
  TriangleMesh world = test::flat_ground(80);
  TriangleMesh car;
  add_box(car, {0, 0}, {2.2f, 0.9f}, 0, 0.3f, 1.5f, test::materials().id("vehicle_paint", "test"));
  RayScene scene(world);
  scene.add_actor(scene.add_prototype(car), Eigen::Isometry3d::Identity());
  scene.commit();
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const ActorPoses moving = [](int64_t t, std::vector<Eigen::Isometry3d>& poses) {
    poses[0] = Eigen::Isometry3d(Eigen::Translation3d(10 + 15.0 * double(t) * 1e-9, 0, 0));
  };
  auto behind_car = [&](const WeatherConfig& w) {
    const LidarScanner scanner(config, test::materials(), w);
    int n = 0;
    for (const auto& p :
         scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, kSeed, moving).points) {
      const Eigen::Vector3d g = world_point(p, config);
      n += g.z() > 0.2 && g.x() > 2 && g.x() < 7.5 && std::abs(g.y()) < 1;  // above the road, behind the car
    }
    return n;
  };
  WeatherConfig wet;
  wet.wet = true;
  wet.spray = true;
  EXPECT_EQ(behind_car({}), 0);
  EXPECT_GT(behind_car(wet), 20);
  wet.wet = false;  // no water on the road, no spray
  EXPECT_EQ(behind_car(wet), 0);
}

TEST(Weather, AParkedCarThrowsNoSprayBesideAMovingOne) {
  // The moving car of the test above and a parked one 5 m to its left: the scanner gives a parked
  // actor to Embree as one pose, and its spray (none) still comes from all its keyframes.
  TriangleMesh world = test::flat_ground(80);
  TriangleMesh car;
  add_box(car, {0, 0}, {2.2f, 0.9f}, 0, 0.3f, 1.5f, test::materials().id("vehicle_paint", "test"));
  RayScene scene(world);
  const int prototype = scene.add_prototype(car);
  scene.add_actor(prototype, Eigen::Isometry3d::Identity());
  scene.add_actor(prototype, Eigen::Isometry3d::Identity());
  scene.commit();
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const ActorPoses poses = [](int64_t t, std::vector<Eigen::Isometry3d>& p) {
    p[0] = Eigen::Isometry3d(Eigen::Translation3d(10 + 15.0 * double(t) * 1e-9, 0, 0));
    p[1] = Eigen::Isometry3d(Eigen::Translation3d(10, 5, 0));
  };
  WeatherConfig wet;
  wet.wet = true;
  wet.spray = true;
  const LidarScanner scanner(config, test::materials(), wet);
  int behind_moving = 0, behind_parked = 0;
  for (const auto& p :
       scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, kSeed, poses).points) {
    const Eigen::Vector3d g = world_point(p, config);
    if (g.z() <= 0.2 || g.x() <= 2 || g.x() >= 7.5) continue;  // above the road, behind the cars
    behind_moving += std::abs(g.y()) < 1;
    behind_parked += std::abs(g.y() - 5) < 1;
  }
  EXPECT_GT(behind_moving, 20);
  EXPECT_EQ(behind_parked, 0);
}

TEST(Weather, ProfilesAndScenarioKeys) {
  EXPECT_TRUE(weather_config_for(Realism::ideal).dry());
  EXPECT_TRUE(weather_config_for(Realism::typical).dry());
  const WeatherConfig harsh = weather_config_for(Realism::harsh);
  EXPECT_TRUE(harsh.wet && harsh.spray && harsh.puddle_fraction > 0 && harsh.rain_rate_mm_h > 0);
  const YamlReader y = YamlReader::from_string("{wet: true, puddle_fraction: 0.1, rain_rate_mm_h: 4}\n", "w.yaml");
  WeatherConfig c;
  read_weather_config(y, y.root(), c);
  EXPECT_TRUE(c.wet);
  EXPECT_EQ(c.puddle_fraction, 0.1);
  EXPECT_EQ(c.rain_rate_mm_h, 4);
  for (const char* text : {"{puddles: 0.1}\n", "{puddle_fraction: 0.9}\n"}) {
    const YamlReader bad = YamlReader::from_string(text, "w.yaml");
    WeatherConfig d;
    EXPECT_THROW(read_weather_config(bad, bad.root(), d), InputError) << text;
  }
}

}  // namespace
}  // namespace lidarloop
