#pragma once
// The driver: follows a path at a target speed profile, stopping where told.
//
// Steering (front wheel angle): the curvature feed-forward of the linear single-track model,
// (L + K v^2) kappa, which is exactly what Eq. 19 needs in a steady turn, plus Stanley feedback on the
// heading error and the front axle's cross-track error. Speed: PI on the speed error, towards a target
// limited by the lateral acceleration allowed on the path's curvature and by a comfortable braking
// distance to the next stop.
//
// The controller is told the pose it should believe (ground truth, or in closed loop the localizer's
// estimate); it never looks at the simulator's state itself.
#include <cstdint>
#include <vector>

#include "sim/path.hpp"
#include "sim/traffic.hpp"  // Wait
#include "sim/vehicle_model.hpp"

namespace lidarloop {

struct ControllerParams {
  double stanley_gain = 1.5;       // 1/s: cross-track error to steering
  double stanley_softening = 1.0;  // m/s: keeps the gain finite at low speed
  double heading_gain = 1.0;
  // rad: the most the cross-track feedback may turn the wheels. Stanley's term alone would steer up to
  // 90 deg towards the path; far off it (a kink, a U-turn) the wheels must then swing faster than the
  // actuator's max_steer_rate, the loop lags and oscillates in growing swings. Capped, a car far off
  // the path comes back along a straight approach; within about a metre of it the cap never binds.
  double max_cross_track_steer = 0.2;
  double preview_s = 0.15;         // look ahead to make up for the steering actuator's lag
  double speed_kp = 0.8;           // (m/s^2) per (m/s)
  double speed_ki = 0.1;           // (m/s^2) per m
  double max_lateral_accel = 2.0;  // m/s^2 on curves
  double comfort_decel = 2.0;      // m/s^2 towards stops
  double stop_tolerance = 0.3;     // m: close enough to a stop line
  // In closed loop, whether the newest estimate is carried to the present with CAN odometry before
  // the controller steers on it, as production stacks compensate a pose's delay (Autoware's EKF
  // localizer and Apollo's MSF both do). false: the car steers on the estimate as it came, its latency
  // uncompensated, as a naive stack would (loop/localizer_loop.cpp).
  bool dead_reckoning = true;
};

struct ControllerCommand {
  VehicleCommand command;
  double progress = 0;     // arc length of the vehicle on its path, m (unwrapped on closed paths)
  double cross_track = 0;  // signed lateral error of the rear axle, m (left positive)
  bool finished = false;   // reached the end of an open path and stopped
};

class PathController {
 public:
  PathController(const Path& path, double cruise_speed, std::vector<Wait> stops, const VehicleParams& vehicle,
                 const ControllerParams& params = {});

  // One control step at time t from the pose the controller believes and the measured speed.
  ControllerCommand update(int64_t t_ns, const Pose2d& rear_axle, double speed);
  // The pose it steers on jumped `along` metres along the path (a kidnap of the car, steered on the
  // truth): the next update looks for the car there, not within a step of where it was.
  void jumped(double along) {
    if (progress_ >= 0) progress_ += along;
  }

 private:
  double project(const Eigen::Vector2d& p, double guess) const;  // arc length near `guess`
  double target_speed(double s, double speed) const;

  Path path_;
  double cruise_;
  std::vector<Wait> stops_;
  VehicleParams vehicle_;
  ControllerParams p_;
  double progress_ = -1;  // unwrapped arc length, -1 before the first update
  double integral_ = 0;
  int64_t last_ns_ = -1;
  size_t next_stop_ = 0;
  int64_t stopped_since_ns_ = -1;
};

}  // namespace lidarloop
