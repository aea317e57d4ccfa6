// smooth_polyline against known truth: a straight line stays put, a kink of angle a becomes a bend of
// peak curvature a / (sqrt(2 pi) sigma) (the heading follows the Gaussian's integral), an arc of
// radius R moves inwards by about sigma^2 / (2 R), and the ends stay where they were.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "common/pose2d.hpp"

#include "sim/path.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

TEST(SmoothPolyline, StraightLineStaysStraightAndEndsStayPut) {
  const Polyline2d line = smooth_polyline({{0, 0}, {10, 5}, {40, 20}}, 1.5, 0.5);
  for (const auto& p : line) EXPECT_NEAR(p.y(), 0.5 * p.x(), 1e-9);
  EXPECT_NEAR(line.front().norm(), 0, 1e-12);
  EXPECT_NEAR((line.back() - Eigen::Vector2d(40, 20)).norm(), 0, 1e-12);
  EXPECT_NEAR(polyline_length(line), std::hypot(40, 20), 1e-9);
}

TEST(SmoothPolyline, KinkBecomesABendOfBoundedCurvature) {
  const double sigma = 1.5, a = 0.5;  // rad
  const Polyline2d line = smooth_polyline({{-50, 0}, {0, 0}, {50 * std::cos(a), 50 * std::sin(a)}}, sigma, 0.1);
  const Path path = make_path(line, false);
  double peak = 0;
  for (double s = 10; s < path.length - 10; s += 0.1) {
    const Pose2d p0 = path.pose_at(s - 0.5), p1 = path.pose_at(s + 0.5);
    peak = std::max(peak, std::abs(wrap_angle(p1.yaw - p0.yaw)));  // per metre
  }
  EXPECT_NEAR(peak, a / (std::sqrt(2 * std::numbers::pi) * sigma), 0.01);
  EXPECT_NEAR(path.pose_at(path.length - 1).yaw, a, 1e-6);  // far from the kink, the heading is the line's
}

TEST(SmoothPolyline, ArcMovesInwardsBySigmaSquaredOverTwoR) {
  const double R = 15, sigma = 1.5;
  Polyline2d arc;
  for (int i = 0; i <= 720; ++i) {
    const double t = std::numbers::pi * i / 720;  // half a circle about the origin
    arc.emplace_back(R * std::cos(t), R * std::sin(t));
  }
  const Polyline2d line = smooth_polyline(arc, sigma, 0.25);
  const Eigen::Vector2d middle = line[line.size() / 2];
  EXPECT_NEAR(R - middle.norm(), sigma * sigma / (2 * R), 0.01);
}

}  // namespace
}  // namespace lidarloop
