#pragma once
// The ego vehicle: the paper's single-track model (Eq. 19) with Table I parameters, actuator limits
// and lags, and the kinematic bicycle model at low speed where Eq. 19 (which divides by v_x) breaks down.
//
// Cornering stiffness is per tyre: Eq. 19 multiplies C_f and C_r by 2 for the two tyres of an axle.
// With Table I (C_f = C_r, l_f > l_r) the car oversteers; its critical speed is
// sqrt(L / -K) ~ 37 m/s, with the understeer gradient K = M/L (l_r/(2 C_f) - l_f/(2 C_r)); keep
// scenario speeds well below it.
#include <array>
#include <cstdint>

#include "common/vehicle_messages.hpp"
#include "common/yaml_reader.hpp"

namespace lidarloop {

struct VehicleParams {
  // Table I of the paper.
  double cornering_stiffness_front = 45980;  // C_f, N/rad per tyre
  double cornering_stiffness_rear = 45980;   // C_r, N/rad per tyre
  double lf = 1.4;                           // centre of mass to front axle, m
  double lr = 1.2;                           // centre of mass to rear axle, m
  double yaw_inertia = 6000;                 // I_z, kg m^2
  double mass = 2300;                        // M, kg
  // Beyond the paper: what a real car's actuators and sensors need.
  double steering_ratio = 16.0;       // steering-wheel angle / front-wheel angle
  double wheel_radius = 0.33;         // m
  double track_width = 1.6;           // m, between left and right wheels
  double max_steer = 0.55;            // rad, front wheel
  double max_steer_rate = 0.5;        // rad/s, front wheel
  double steer_time_constant = 0.10;  // s, first-order lag of the steering actuator
  double max_accel = 2.5;             // m/s^2
  double max_decel = 6.0;             // m/s^2 (positive number)
  double accel_time_constant = 0.25;  // s, first-order lag of drive and brakes
  double max_speed = 25.0;            // m/s
  double kinematic_below = 1.5;       // m/s: kinematic model below, Eq. 19 above (blended over 1 m/s)
  int64_t step_ns = 1'000'000;        // internal integration step (at most 1 ms)

  double wheelbase() const { return lf + lr; }
};

// Reads overrides (keys as the field names) and validates them; file:line:col on errors.
void read_vehicle_params(const YamlReader& yaml, const YAML::Node& node, VehicleParams& params);
VehicleParams load_vehicle_params(const std::string& path);  // e.g. assets/vehicle.yaml

struct VehicleState {
  double x = 0, y = 0;  // centre of mass, local frame, m
  double yaw = 0;       // psi, rad
  double vx = 0;        // longitudinal speed, m/s (never negative: no reversing)
  double beta = 0;      // side-slip angle at the centre of mass, rad
  double yaw_rate = 0;  // psi dot, rad/s
  double steer = 0;     // front wheel angle delta_f actually reached by the actuator, rad
  double accel = 0;     // longitudinal acceleration actually reached, m/s^2
};

struct VehicleCommand {
  double steer = 0;  // requested front wheel angle, rad (positive = left)
  double accel = 0;  // requested longitudinal acceleration, m/s^2 (negative = braking)
};

class VehicleModel {
 public:
  VehicleModel(const VehicleParams& params, const VehicleState& initial);
  // Places the vehicle with its rear axle centre (the vehicle frame origin) at `pose`, at rest or at `speed`.
  static VehicleState state_at(const VehicleParams& params, const Pose2d& rear_axle, double speed);

  void step(const VehicleCommand& command);  // advances by params().step_ns
  // Sets the car down with its rear axle centre at `rear_axle`, moving as it was (speed, slip, yaw
  // rate, steering, acceleration kept): a kidnap of the car.
  void place(const Pose2d& rear_axle);
  const VehicleState& state() const { return state_; }
  const VehicleParams& params() const { return params_; }

  Pose2d rear_axle_pose() const;               // the vehicle frame origin
  std::array<double, 4> wheel_speeds() const;  // FL, FR, RL, RR: ground speed along each wheel, m/s
  double steering_wheel_angle() const { return state_.steer * params_.steering_ratio; }

 private:
  VehicleParams params_;
  VehicleState state_;
};

// Steady-state turning radius of the linear single-track model at `speed` with front wheel angle
// `steer`: R = (L + K v^2) / steer (the closed form the dynamic model must reproduce).
double steady_state_radius(const VehicleParams& params, double speed, double steer);

}  // namespace lidarloop
