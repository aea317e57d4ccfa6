// The return model: intensity from reflectivity, incidence and range; retro-reflectors; dropouts.
#include <gtest/gtest.h>

#include "sim/lidar_return.hpp"
#include "sim/lidar_scanner.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

int intensity(const ReturnModel& model, const std::string& material, double range, double cos_incidence) {
  const auto r =
      model(test::materials()[test::materials().id(material, "test")], range, cos_incidence, 5, CounterRng(1, 2), 3);
  return r ? r->intensity : -1;
}

TEST(LidarReturns, PaintIsBrighterThanAsphaltAtEqualRangeAndIncidence) {
  const ReturnModel model(test::noiseless_hdl32e());
  for (double range : {5.0, 15.0, 30.0})
    for (double cos_incidence : {0.9, 0.3, 0.1}) {
      const int paint = intensity(model, "lane_paint", range, cos_incidence);
      const int asphalt = intensity(model, "asphalt", range, cos_incidence);
      EXPECT_GT(paint, 3 * asphalt) << range << " m, cos " << cos_incidence;
      EXPECT_GT(asphalt, 0);
    }
}

TEST(LidarReturns, IntensityFallsWithIncidenceAngle) {
  const ReturnModel model(test::noiseless_hdl32e());
  int previous = 256;
  for (double incidence_deg : {0, 30, 50, 70, 85}) {
    const int i = intensity(model, "crosswalk_paint", 10.0, std::cos(incidence_deg * M_PI / 180));
    EXPECT_LT(i, previous) << incidence_deg << " deg";
    previous = i;
  }
}

TEST(LidarReturns, RetroReflectorsReadAbove100AndDiffuseSurfacesAtMost100) {
  const ReturnModel model(test::noiseless_hdl32e());
  EXPECT_GT(intensity(model, "retro_reflector", 40.0, 0.5), 100);
  EXPECT_LE(intensity(model, "grass", 2.0, 1.0), 100);
  // A diffuse target of reflectivity rho at normal incidence and reference range reads ~100 rho.
  EXPECT_NEAR(intensity(model, "building", 10.0, 1.0), 100 * 0.40,
              100 * 0.40 * test::noiseless_hdl32e().laser_gain_spread + 1);
}

TEST(LidarReturns, WeakAndGrazingReturnsAreLost) {
  const Hdl32eConfig config;  // the real detection model
  const ReturnModel model(config);
  // Dark asphalt seen at a grazing angle far away is lost; a wall facing the sensor is not.
  EXPECT_EQ(intensity(model, "asphalt", 60.0, 1.9 / 60.0), -1);
  EXPECT_GT(intensity(model, "building", 60.0, 1.0), 0);
  EXPECT_EQ(intensity(model, "building", 10.0, std::cos(89.0 * M_PI / 180)), -1);
  // Beyond the maximum range nothing comes back.
  EXPECT_EQ(intensity(model, "retro_reflector", config.max_range_m + 1, 1.0), -1);
}

TEST(LidarReturns, PaintStripeStandsOutInAScan) {
  // Asphalt with one 0.15 m lane line 3 m to the left, along the direction of travel.
  TriangleMesh mesh = test::flat_ground(40);
  const MaterialId paint = test::materials().id("lane_paint", "test");
  add_flat_quad(mesh,
                {Eigen::Vector2f(-40, 2.925f), Eigen::Vector2f(40, 2.925f), Eigen::Vector2f(40, 3.075f),
                 Eigen::Vector2f(-40, 3.075f)},
                0.003f, paint);
  RayScene scene(mesh);
  const Hdl32eConfig config;
  const LidarScanner scanner(config, test::materials());
  const PointCloud cloud = scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, 3);
  double on = 0, off = 0;
  int n_on = 0, n_off = 0;
  for (const auto& p : cloud.points) {
    const double y = p.y + config.mount_xyz.y(), x = p.x + config.mount_xyz.x();
    if (p.z > -1.5 || std::abs(x) > 15) continue;
    if (std::abs(y - 3.0) < 0.05)
      on += p.intensity, ++n_on;
    else if (std::abs(y - 3.0) > 0.3 && std::abs(y - 3.0) < 1.0)
      off += p.intensity, ++n_off;
  }
  ASSERT_GT(n_on, 20);
  ASSERT_GT(n_off, 100);
  EXPECT_GT(on / n_on, 3.0 * off / n_off);
}

}  // namespace
}  // namespace lidarloop
