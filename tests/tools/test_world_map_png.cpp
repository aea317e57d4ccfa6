// The world's top view: curb lines are drawn in their kind's colour where the world has them.
#include <gtest/gtest.h>

#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "test_support.hpp"
#include "tools/world_map_png.hpp"

namespace lidarloop {
namespace {

// Does any pixel within `radius` of (x, y) metres have exactly the colour `bgr`?
bool colour_near(const cv::Mat& image, const World& w, double resolution, double x, double y, const cv::Scalar& bgr) {
  constexpr int kRadius = 3;  // pixels
  const int px = int(std::lround((x - w.bounds.min().x()) / resolution));
  const int py = image.rows - 1 - int(std::lround((y - w.bounds.min().y()) / resolution));
  for (int dy = -kRadius; dy <= kRadius; ++dy)
    for (int dx = -kRadius; dx <= kRadius; ++dx) {
      const int u = px + dx, v = py + dy;
      if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
      const cv::Vec3b c = image.at<cv::Vec3b>(v, u);
      if (c[0] == bgr[0] && c[1] == bgr[1] && c[2] == bgr[2]) return true;
    }
  return false;
}

TEST(WorldMapPng, CurbLinesAreColouredByKindWithTheirCutsWhereTheyAre) {
  // A straight road with a crosswalk at x = 40: its curbs are cut for ramps there, vertical elsewhere.
  const World w = test::world_from_yaml(R"(name: png
origin: {lat: 31.28, lon: 121.21}
roads:
  - {name: main, points: [[0, 0], [80, 0]], width: 8}
crosswalks:
  - {road: main, at: 40, width: 4}
)");
  constexpr double kResolution = 0.1;
  const std::string path = testing::TempDir() + "/world_kinds.png";
  write_world_map_png(path, w, test::materials(), kResolution);
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const cv::Scalar ramp = curb_colour("ramp"), vertical = curb_colour("vertical");
  for (double y : {-4.0, 4.0}) {
    EXPECT_TRUE(colour_near(image, w, kResolution, 40, y, ramp)) << y;
    EXPECT_FALSE(colour_near(image, w, kResolution, 40, y, vertical)) << y;
    EXPECT_TRUE(colour_near(image, w, kResolution, 20, y, vertical)) << y;
    EXPECT_FALSE(colour_near(image, w, kResolution, 20, y, ramp)) << y;
  }
}

}  // namespace
}  // namespace lidarloop
