// The one planar pose type: composition, inverse and relative pose on cases worked by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "common/pose2d.hpp"
#include "common/units.hpp"

namespace lidarloop {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(WrapAngle, MapsIntoTheHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(3 * kPi / 2), -kPi / 2);
  EXPECT_DOUBLE_EQ(wrap_angle(-3 * kPi / 2), kPi / 2);
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);  // (-pi, pi]: -pi becomes +pi
  EXPECT_DOUBLE_EQ(wrap_angle(0.25 + 6 * kPi), 0.25);
}

TEST(Pose2d, ApplyRotatesThenTranslates) {
  const Pose2d quarter{1, 2, kPi / 2};  // at (1, 2), facing +y
  const Eigen::Vector2d p = quarter.apply({3, 0});
  EXPECT_NEAR(p.x(), 1, 1e-12);  // 3 m ahead of a car facing north is 3 m north of it
  EXPECT_NEAR(p.y(), 5, 1e-12);
}

TEST(Pose2d, ComposeAppliesTheRightOperandFirst) {
  const Pose2d a{10, -4, 30 * kDeg}, b{2, 1, 100 * kDeg};
  const Eigen::Vector2d p(0.7, -1.3);
  const Eigen::Vector2d direct = a.apply(b.apply(p)), composed = a.compose(b).apply(p);
  EXPECT_NEAR((direct - composed).norm(), 0, 1e-12);
  EXPECT_NEAR(a.compose(b).yaw, 130 * kDeg, 1e-12);
  // Angles wrap: 170 + 20 deg is -170 deg.
  const Pose2d turned = Pose2d{0, 0, 170 * kDeg}.compose(Pose2d{0, 0, 20 * kDeg});
  EXPECT_NEAR(turned.yaw, -170 * kDeg, 1e-12);
}

TEST(Pose2d, InverseUndoesThePose) {
  const Pose2d a{-3, 8, -2.5};
  const Pose2d identity = a.compose(a.inverse());
  EXPECT_NEAR(identity.x, 0, 1e-12);
  EXPECT_NEAR(identity.y, 0, 1e-12);
  EXPECT_NEAR(identity.yaw, 0, 1e-12);
}

TEST(Pose2d, RelativeIsTheMotionFromOnePoseToAnother) {
  // A car at (5, 5) facing north drives 2 m forward and turns left by 10 degrees.
  const Pose2d before{5, 5, kPi / 2}, after{5, 7, kPi / 2 + 10 * kDeg};
  const Pose2d motion = relative(before, after);
  EXPECT_NEAR(motion.x, 2, 1e-12);  // forward, in the car's own frame
  EXPECT_NEAR(motion.y, 0, 1e-12);
  EXPECT_NEAR(motion.yaw, 10 * kDeg, 1e-12);
  const Pose2d again = before.compose(motion);
  EXPECT_NEAR(again.x, after.x, 1e-12);
  EXPECT_NEAR(again.y, after.y, 1e-12);
  EXPECT_NEAR(again.yaw, after.yaw, 1e-12);
}

}  // namespace
}  // namespace lidarloop
