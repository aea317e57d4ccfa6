// The points a driver makes of HDL-32E blocks (common/hdl32e_driver.hpp), against hand-computed ones.
#include <cmath>

#include <gtest/gtest.h>

#include "common/hdl32e_driver.hpp"
#include "common/units.hpp"

namespace lidarloop {
namespace {

// A calibration whose channel c looks at c - 16 degrees and is ring 31 - c.
Hdl32eCalibration test_calibration() {
  Hdl32eCalibration c;
  for (int k = 0; k < kHdl32eChannels; ++k) {
    c.ring[size_t(k)] = uint16_t(31 - k);
    c.cos_elevation[size_t(k)] = std::cos((k - 16) * kDeg);
    c.sin_elevation[size_t(k)] = std::sin((k - 16) * kDeg);
  }
  c.firing_period_ns = 1152;
  c.cycle_period_ns = 46080;
  return c;
}

TEST(Hdl32eDriver, AReturnIsPlacedAtItsBlocksAzimuthAndItsChannelsElevation) {
  std::vector<Hdl32eBlock> blocks(3);
  // Block 2 at azimuth 90 deg (clockwise from ahead: to the right, -y), channel 16 (level) at 10 m,
  // channel 46 - 16 = 30 (+14 deg) at 20 m; every other channel empty.
  blocks[2].azimuth = 9000;
  blocks[2].distance[16] = 5000;
  blocks[2].intensity[16] = 42;
  blocks[2].distance[30] = 10000;
  const PointCloud cloud = hdl32e_cloud(test_calibration(), 123'000'000, blocks);
  EXPECT_EQ(cloud.stamp_ns, 123'000'000);
  ASSERT_EQ(cloud.points.size(), 2u);
  const LidarPoint& level = cloud.points[0];
  EXPECT_NEAR(level.x, 0.0, 1e-6);
  EXPECT_NEAR(level.y, -10.0, 1e-6);
  EXPECT_NEAR(level.z, 0.0, 1e-6);
  EXPECT_EQ(level.intensity, 42);
  EXPECT_EQ(level.ring, 15);
  EXPECT_EQ(level.t_ns, 2u * 46080u + 16u * 1152u);
  const LidarPoint& up = cloud.points[1];
  EXPECT_NEAR(up.y, -20.0 * std::cos(14 * kDeg), 1e-5);
  EXPECT_NEAR(up.z, 20.0 * std::sin(14 * kDeg), 1e-5);
  EXPECT_EQ(up.ring, 1);
  EXPECT_EQ(up.t_ns, 2u * 46080u + 30u * 1152u);
}

TEST(Hdl32eDriver, BlocksWithoutReturnsGiveAnEmptyCloud) {
  const std::vector<Hdl32eBlock> blocks(2170);
  EXPECT_TRUE(hdl32e_cloud(test_calibration(), 0, blocks).points.empty());
}

}  // namespace
}  // namespace lidarloop
