// The body's roll from CAN and the scan turned back from it: a steady bend's roll is the car's roll
// gradient times the lateral acceleration, reached as a second-order mode overshoots; and a road seen
// from a body rolled about its pivot (as the simulator's body model poses it) is put back where it lies.
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "common/units.hpp"
#include "common/vehicle_messages.hpp"
#include "localizer/body_roll.hpp"

namespace lidarloop {
namespace {

TEST(BodyRoll, ASteadyBendRollsTheBodyByItsGradientAfterTheModesOvershoot) {
  const BodyRollParams params;  // 5 deg/g, 1.5 Hz, damping 0.3
  BodyRoll body(params);
  const double a_y = 0.3 * kGravity;  // a left bend at 0.3 g, from rest
  double peak = 0;
  for (int k = 0; k < 1000; ++k) {  // 10 s at CAN's 100 Hz
    body.step(a_y, 0.01);
    peak = std::max(peak, body.roll());
  }
  const double steady = 1.5 * kDeg;  // 5 deg/g * 0.3 g, left side up
  EXPECT_NEAR(body.roll(), steady, 0.005 * steady);
  // A step into a second-order mode overshoots by exp(-z pi / sqrt(1 - z^2)): 37 % at z = 0.3.
  const double z = params.damping_ratio;
  EXPECT_NEAR(peak / steady, 1 + std::exp(-z * std::numbers::pi / std::sqrt(1 - z * z)), 0.01);
  // Out of the bend it swings back through level (the same overshoot) within half a period...
  BodyRoll leaving = body;
  leaving.step(0.0, 0.5 / params.frequency_hz);
  EXPECT_LT(leaving.roll(), -0.2 * steady);
  // ...and after a long gap in CAN it is at rest, whatever came before.
  body.step(0.0, 1e9);
  EXPECT_EQ(body.roll(), 0.0);
  body.step(std::numeric_limits<double>::quiet_NaN(), 0.01);  // bad input leaves it as it was
  EXPECT_EQ(body.roll(), 0.0);

  BodyRollParams off = params;
  off.enabled = false;
  BodyRoll rigid(off);
  rigid.step(a_y, 5.0);
  EXPECT_EQ(rigid.roll(), 0.0);
}

TEST(BodyRoll, UnrollPutsTheRoadSeenFromTheRolledBodyBackWhereItLies) {
  // Curb and road points in the vehicle frame (the ground under the wheels), seen from a body rolled
  // 1.5 deg left side up about its centre of mass 0.7 m up (BodyAttitude: the simulator's pose of it).
  BodyAttitude body;
  body.roll = 1.5 * kDeg;
  body.pivot = Eigen::Vector3d(1.2, 0, 0.7);
  const std::vector<Eigen::Vector3d> truth = {{5, -4, 0.15}, {10, 4, 0.0}, {-3, 2.5, 0.02}, {20, -1.6, 0.0}};
  std::vector<Eigen::Vector3d> seen;
  for (const Eigen::Vector3d& p : truth) seen.push_back(body.pose().inverse() * p);
  // Read from the body as if it were level, the road is 2 cm off sideways: about roll times pivot height.
  EXPECT_NEAR(seen[1].y() - truth[1].y(), -0.7 * std::sin(body.roll), 2e-3);
  EXPECT_LT(seen[1].y() - truth[1].y(), -0.015);
  unroll(seen, body.roll, 0.7);
  for (size_t i = 0; i < truth.size(); ++i) EXPECT_LT((seen[i] - truth[i]).norm(), 1e-12) << i;
}

}  // namespace
}  // namespace lidarloop
