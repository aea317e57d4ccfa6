#include "sim/controller.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop {

constexpr double kProjectBehind = 3.0, kProjectAhead = 10.0;  // m: where the car can be one step later
constexpr double kCurvatureLookStep = 2.0;                    // m between curvature samples ahead
constexpr double kStandstill = 0.05;                          // m/s
constexpr double kHoldBrake = -1.0;                           // m/s^2 while standing
constexpr double kIntegralLimit = 3.0;                        // m: anti-windup of the speed PI
constexpr double kFeedForwardHorizon = 0.2;                   // s over which the target's slope is taken

PathController::PathController(const Path& path, double cruise_speed, std::vector<Wait> stops,
                               const VehicleParams& vehicle, const ControllerParams& params)
    : path_(path), cruise_(cruise_speed), stops_(std::move(stops)), vehicle_(vehicle), p_(params) {
  std::sort(stops_.begin(), stops_.end(), [](const Wait& a, const Wait& b) { return a.at < b.at; });
}

double PathController::project(const Eigen::Vector2d& p, double guess) const {
  return path_.project(p, guess - kProjectBehind, guess + kProjectAhead);
}

double PathController::target_speed(double s, double speed) const {
  double v = cruise_;
  // Curvature ahead, as far as it takes to brake comfortably from the current speed.
  const double horizon = speed * speed / (2 * p_.comfort_decel) + kCurvatureLookStep;
  for (double ahead = 0; ahead <= horizon; ahead += kCurvatureLookStep) {
    const double kappa = std::abs(path_.curvature_at(s + ahead));
    if (kappa > 1e-6) {
      const double v_curve = std::sqrt(p_.max_lateral_accel / kappa);
      // Allowed now: what still lets us brake to v_curve by the time we get there.
      v = std::min(v, std::sqrt(v_curve * v_curve + 2 * p_.comfort_decel * ahead));
    }
  }
  auto brake_for = [&](double distance) {
    v = std::min(v, std::sqrt(std::max(0.0, 2 * p_.comfort_decel * (distance - p_.stop_tolerance / 2))));
  };
  if (next_stop_ < stops_.size()) brake_for(stops_[next_stop_].at - s);
  if (!path_.closed) brake_for(path_.length - s);
  return v;
}

ControllerCommand PathController::update(int64_t t_ns, const Pose2d& rear, double speed) {
  const double dt = last_ns_ < 0 ? 0.0 : double(t_ns - last_ns_) * 1e-9;
  last_ns_ = t_ns;
  const Eigen::Vector2d rear_xy(rear.x, rear.y);
  progress_ = progress_ < 0 ? path_.project(rear_xy) : project(rear_xy, progress_);

  // Steering. Steady-state cornering on the single-track model (Eq. 19 with beta dot = psi double
  // dot = 0) needs the front wheel angle (L + K v^2) kappa, with the understeer gradient K, and leaves
  // the body pointing inside the path by the rear tyres' slip angle alpha_r = M l_f v^2 kappa / (2 C_r L).
  // That is the feed-forward (taken a little ahead, for the steering lag); feedback on the rear axle's
  // heading and cross-track errors (Stanley-like, critically damped around 2-3 rad/s) handles the rest.
  const double wheelbase = vehicle_.wheelbase();
  const Pose2d on_path = path_.pose_at(progress_);
  const Eigen::Vector2d left(-std::sin(on_path.yaw), std::cos(on_path.yaw));
  const double cross_track = (rear_xy - Eigen::Vector2d(on_path.x, on_path.y)).dot(left);
  const double kappa = path_.curvature_at(progress_ + speed * p_.preview_s);
  const double a_lat = speed * speed * kappa;
  const double K =
      vehicle_.mass / wheelbase *
      (vehicle_.lr / (2 * vehicle_.cornering_stiffness_front) - vehicle_.lf / (2 * vehicle_.cornering_stiffness_rear));
  const double rear_slip = vehicle_.mass * vehicle_.lf * a_lat / (2 * vehicle_.cornering_stiffness_rear * wheelbase);
  const double feed_forward = std::atan(wheelbase * kappa) + K * a_lat;
  const double heading_error = wrap_angle(on_path.yaw + rear_slip - rear.yaw);
  const double cross_track_steer = std::clamp(std::atan2(p_.stanley_gain * cross_track, speed + p_.stanley_softening),
                                              -p_.max_cross_track_steer, p_.max_cross_track_steer);
  const double steer = feed_forward + p_.heading_gain * heading_error - cross_track_steer;

  // Speed.
  ControllerCommand out;
  out.progress = progress_;
  out.cross_track = cross_track;
  if (next_stop_ < stops_.size()) {
    const Wait& stop = stops_[next_stop_];
    const bool at_stop = std::abs(stop.at - progress_) <= p_.stop_tolerance || progress_ > stop.at;
    if (at_stop && speed < kStandstill) {
      if (stopped_since_ns_ < 0) stopped_since_ns_ = t_ns;
      if (double(t_ns - stopped_since_ns_) * 1e-9 >= stop.duration_s) ++next_stop_, stopped_since_ns_ = -1;
    }
  }
  // Aim where the car will be once the drive or brakes have responded, and follow the target's slope
  // along the path as a feed-forward acceleration; PI takes care of the rest.
  const double lag_distance = speed * vehicle_.accel_time_constant;
  const double v_target = target_speed(progress_ + lag_distance, speed);
  const double v_next = target_speed(progress_ + lag_distance + speed * kFeedForwardHorizon, speed);
  const double accel_ff = (v_next - v_target) / kFeedForwardHorizon;
  if (v_target < kStandstill && speed < kStandstill) {
    integral_ = 0;
    out.command = {steer, kHoldBrake};
    out.finished = !path_.closed && path_.length - progress_ <= p_.stop_tolerance;
    return out;
  }
  const double error = v_target - speed;
  integral_ = std::clamp(integral_ + error * dt, -kIntegralLimit, kIntegralLimit);
  out.command = {steer, accel_ff + p_.speed_kp * error + p_.speed_ki * integral_};
  return out;
}

}  // namespace lidarloop
