// The localizer's body roll (localizer/body_roll.hpp), fed what it has (the rear wheels' speed and the
// steering as CAN reports them, through its own Eq. 19), against the simulated car's body
// (sim/vehicle_body.hpp) driven by the car's true acceleration: the same roll into and around a bend,
// with the same sign.
#include <cmath>

#include <gtest/gtest.h>

#include "localizer/body_roll.hpp"
#include "localizer/pose_filter.hpp"
#include "sim/vehicle_body.hpp"
#include "sim/vehicle_model.hpp"

namespace lidarloop {
namespace {

TEST(BodyRollFollowsTheCar, IntoAndAroundALeftBend) {
  const VehicleParams vp;
  VehicleModel car(vp, VehicleModel::state_at(vp, {0, 0, 0}, 8.0));
  VehicleBody body(BodyConfig{}, vp, GroundPlane{});
  MotionPredictor predictor(VehicleModelParams{});
  BodyRoll roll(BodyRollParams{});
  Pose2d odometry = car.rear_axle_pose();
  const double dt = 0.01;                // CAN at 100 Hz
  const VehicleCommand turn{0.08, 0.0};  // a left bend of ~33 m at 8 m/s: about 0.2 g
  double worst = 0, steady_truth = 0, steady_ours = 0;
  for (int k = 0; k < 500; ++k) {  // 5 s
    for (int s = 0; s < 10; ++s) {
      const VehicleState before = car.state();
      car.step(turn);
      body.step(1e-3, planar_acceleration(before, car.state(), 1e-3), GroundPlane{});
    }
    const auto wheels = car.wheel_speeds();
    odometry = predictor.predict(odometry, 0.5 * (wheels[2] + wheels[3]), car.state().steer, dt);
    roll.step(predictor.lateral_acceleration(), dt);
    worst = std::max(worst, std::abs(roll.roll() - body.attitude().roll));
    steady_truth = body.attitude().roll;
    steady_ours = roll.roll();
  }
  EXPECT_GT(steady_truth, 0.5 * kDeg);  // left side up, as a left bend rolls a car
  EXPECT_NEAR(steady_ours, steady_truth, 0.03 * steady_truth);
  // Into the bend the steering's lag and the mode's overshoot are followed too.
  EXPECT_LT(worst, 0.1 * steady_truth);
}

}  // namespace
}  // namespace lidarloop
