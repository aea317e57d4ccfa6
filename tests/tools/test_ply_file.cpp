// The PLY writer and reader of `scan --out` and `simulate`.
#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "tools/ply_file.hpp"

namespace lidarloop {
namespace {

TEST(PlyFile, RoundTripKeepsEveryField) {
  PointCloud cloud;
  cloud.stamp_ns = 123456789012;
  cloud.points = {{1.5f, -2.25f, 0.125f, 37, 4, 46080}, {-80.0f, 3.0f, -1.9f, 212, 31, 99996928}};
  const std::string path = testing::TempDir() + "/roundtrip.ply";
  write_ply(path, cloud);
  const PointCloud back = read_ply(path);
  EXPECT_EQ(back.stamp_ns, cloud.stamp_ns);
  ASSERT_EQ(back.points.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.points[i].x, cloud.points[i].x);
    EXPECT_EQ(back.points[i].z, cloud.points[i].z);
    EXPECT_EQ(back.points[i].intensity, cloud.points[i].intensity);
    EXPECT_EQ(back.points[i].ring, cloud.points[i].ring);
    EXPECT_NEAR(double(back.points[i].t_ns), double(cloud.points[i].t_ns), 8.0);  // float seconds in the file
  }
  const std::string not_ply = LIDARLOOP_DATA_DIR "/maps/campus/world.yaml";
  EXPECT_THROW(read_ply(not_ply), InputError);
}

}  // namespace
}  // namespace lidarloop
