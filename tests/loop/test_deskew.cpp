// De-skewing a scan taken while driving and turning: the world comes out straight again.
#include <iostream>

#include <gtest/gtest.h>

#include "localizer/deskew.hpp"
#include "sim/lidar_scanner.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// A wall ahead, perpendicular to the road; the car drives at it and turns slightly during the scan.
// Returns the wall's spread in x (vehicle frame at the scan's end) among the points of the horizontal
// ring near the car's heading, early and late in the scan.
double wall_spread(bool compensate, double speed, double yaw_rate) {
  TriangleMesh mesh = test::flat_ground(60);
  test::add_wall(mesh, {25, 0}, {0.5f, 20}, 10);
  Hdl32eConfig config = test::noiseless_hdl32e();
  config.scan_start_yaw_deg = 0;  // first and last firings look straight ahead
  RayScene scene(mesh);
  const LidarScanner scanner(config, test::materials());
  const PointCloud cloud = scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, speed, yaw_rate), 0, 1);
  const int64_t end = config.cycles_per_scan() * config.cycle_period_ns();
  // Where the car is at the end of the scan, to put the truth in the same frame.
  const Eigen::Isometry3d end_pose = constant_twist(Eigen::Isometry3d::Identity(), 0, speed, yaw_rate)(end);
  const auto points =
      compensate ? deskew(cloud, config.mount(), {speed, yaw_rate}, end) : to_vehicle_frame(cloud, config.mount());
  double lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const LidarPoint& p = cloud.points[i];
    if (p.ring != 23 || std::abs(p.y) > 1.0) continue;
    const bool early = p.t_ns<2'000'000, late = int64_t(p.t_ns)> end - 2'000'000;
    if (!early && !late) continue;
    // The wall's face is the world plane x = 24.5: compare in the world through the end pose.
    const Eigen::Vector3d world = end_pose * points.xyz[i];
    lo = std::min(lo, world.x()), hi = std::max(hi, world.x());
  }
  return hi - lo;
}

TEST(Deskew, CompensatedScansSeeTheWallWhereItIs) {
  // At 10 m/s with 0.2 rad/s of yaw the raw scan puts the wall ~1 m apart between its first and last
  // firings; after de-skew they agree within 2 cm.
  const double raw = wall_spread(false, 10.0, 0.2), turning = wall_spread(true, 10.0, 0.2),
               straight = wall_spread(true, 10.0, 0.0);
  std::cout << "[ figures  ] wall spread: raw " << raw << " m, de-skewed " << turning << " m (turning), " << straight
            << " m (straight)\n";
  EXPECT_GT(raw, 0.8);
  EXPECT_LT(turning, 0.02);
  EXPECT_LT(straight, 0.02);
}

TEST(Deskew, NonFinitePointsAreDropped) {
  PointCloud cloud;
  cloud.points = {{1, 2, 3, 10, 0, 0}, {NAN, 0, 0, 10, 0, 1152}, {4, 5, 6, 10, 1, 1152}};
  const ScanPoints kept = deskew(cloud, Eigen::Isometry3d::Identity(), {5, 0}, 0);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.dropped, 1u);
  // Ring and intensity stay with their point.
  EXPECT_EQ(kept.ring[1], 1);
  EXPECT_EQ(kept.intensity[1], 10);
  EXPECT_EQ(to_vehicle_frame(cloud, Eigen::Isometry3d::Identity()).size(), 2u);
  EXPECT_EQ(deskew(PointCloud{}, Eigen::Isometry3d::Identity(), {5, 0}, 0).size(), 0u);
}

}  // namespace
}  // namespace lidarloop
