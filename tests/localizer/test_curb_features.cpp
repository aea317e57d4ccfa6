// Multi-frame curb accumulation (Eq. 4-5), obstacle-region rejection and the beam model (Eq. 6-7).
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "localizer/curb_features.hpp"

namespace lidarloop {
namespace {

TEST(CurbFeatures, FramesStackOnTheTrueCurbWithKnownOdometry) {
  // The vehicle drives a gentle left curve; the curb is the world line y = -4 (x in [-50, 50]).
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  CurbAccumulator acc(5);
  Eigen::Vector2d position(0, 0);
  double heading = 0;
  for (int frame = 0; frame < 8; ++frame) {
    // Motion since the previous frame, in the previous vehicle frame.
    const Pose2d step{frame == 0 ? 0.0 : 1.0, frame == 0 ? 0.0 : 0.05, frame == 0 ? 0.0 : 0.01};
    position += Eigen::Rotation2D<double>(heading) * Eigen::Vector2d(step.x, step.y);
    heading += step.yaw;
    // This frame's detections: points of the curb within 15 m, seen in the vehicle frame.
    std::vector<Eigen::Vector2d> seen;
    for (double x = position.x() - 15; x < position.x() + 15; x += 0.5) {
      const Eigen::Vector2d local = Eigen::Rotation2D<double>(-heading) * (Eigen::Vector2d(x, -4) - position);
      seen.push_back(local + Eigen::Vector2d(noise(rng), noise(rng)));
    }
    acc.add(seen, step);
  }
  const auto stacked = acc.curbs();
  EXPECT_EQ(stacked.size(), 5u * 60u);
  for (const auto& c : stacked) {
    const Eigen::Vector2d world = position + Eigen::Rotation2D<double>(heading) * c;
    ASSERT_NEAR(world.y(), -4.0, 0.02);  // all frames agree within 2 cm
  }
  // The launch points are the vehicle's past positions, in the current frame.
  ASSERT_EQ(acc.launch_points().size(), 5u);
  EXPECT_NEAR(acc.launch_points()[1].norm(), std::hypot(1.0, 0.05), 0.01);
}

TEST(CurbFeatures, CurbsNextToObstaclesAreRejected) {
  const std::vector<Eigen::Vector2d> curbs = {{5, -4}, {10, -4}, {15, -4}};
  const std::vector<Eigen::Vector2d> car = {{10, -3.7}, {10.5, -3.6}};  // a tyre at the curb
  const auto kept = reject_near_obstacles(curbs, car, 0.5);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0], Eigen::Vector2d(5, -4));
  EXPECT_EQ(kept[1], Eigen::Vector2d(15, -4));
}

TEST(CurbFeatures, ObstacleRejectionAgreesWithTheDefinitionAndIgnoresNonFinitePoints) {
  // A thousand obstacle points against curbs along two lines: about a third of the curbs stay.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> along(-30, 30), across(-6, 6);
  std::vector<Eigen::Vector2d> curbs, obstacles;
  for (int k = 0; k < 400; ++k) curbs.push_back({along(rng), k % 2 ? -4.0 : 4.0});
  for (int k = 0; k < 1000; ++k) obstacles.push_back({along(rng), across(rng)});
  obstacles.push_back({std::nan(""), 0.0});
  const auto kept = reject_near_obstacles(curbs, obstacles, 0.5);
  std::vector<Eigen::Vector2d> expected;
  for (const auto& c : curbs) {
    bool near = false;
    for (const auto& o : obstacles) near |= o.allFinite() && (c - o).norm() <= 0.5;
    if (!near) expected.push_back(c);
  }
  EXPECT_EQ(kept, expected);
  EXPECT_GT(expected.size(), 0u);
  EXPECT_LT(expected.size(), curbs.size());
  EXPECT_EQ(reject_near_obstacles(curbs, obstacles, 0.0), curbs);  // d_o = 0: keep them all
}

TEST(CurbFeatures, TheBeamModelKeepsTheNearestCurbInEachBeam) {
  // Two rings of "curbs" around the vehicle: the inner one at 5 m hides the outer one at 10 m.
  std::vector<Eigen::Vector2d> curbs;
  for (int k = 0; k < 360; ++k) {
    const double a = k * M_PI / 180;
    curbs.emplace_back(10 * std::cos(a), 10 * std::sin(a));
    curbs.emplace_back(5 * std::cos(a), 5 * std::sin(a));
  }
  curbs.emplace_back(30, 0);  // outside the +-25 m box
  const CurbFeatureParams p;
  const auto contour = beam_model(curbs, {Eigen::Vector2d::Zero()}, p);
  EXPECT_EQ(contour.size(), size_t(p.beams));  // one per beam
  for (const auto& c : contour) EXPECT_NEAR(c.norm(), 5.0, 1e-9);
}

}  // namespace
}  // namespace lidarloop
