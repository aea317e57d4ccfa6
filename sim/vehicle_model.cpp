#include "sim/vehicle_model.hpp"
#include "common/units.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace lidarloop {

namespace {

constexpr double kTyresPerAxle = 2;         // Eq. 19's "2 C": the stiffness parameters are per tyre
constexpr double kBlendWidth = 1.0;         // m/s: kinematic -> Eq. 19 over kinematic_below -+ half of this
constexpr double kNegligibleWeight = 1e-6;  // Eq. 19's weight below which its states are reset (see step())
constexpr int64_t kMinStepNs = 10'000;      // 10 us
constexpr int64_t kMaxStepNs = 1'000'000;   // 1 ms: Eq. 19 is stiff at low speed (time constants ~10 ms)

// How much of the motion comes from Eq. 19 (1) rather than the kinematic bicycle (0): linear in speed.
double dynamic_weight(const VehicleParams& p, double vx) {
  const double low = p.kinematic_below - kBlendWidth / 2;
  return std::clamp((vx - low) / kBlendWidth, 0.0, 1.0);
}

struct Slip {
  double beta = 0;      // side slip at the centre of mass, rad
  double yaw_rate = 0;  // rad/s
};

// Kinematic bicycle (no tyre slip) referred to the centre of mass. Its rear axle moves along the body
// x axis at vx (every point on the centre line shares the body-x velocity), so yaw_rate = vx tan(delta) / L,
// i.e. v cos(beta) tan(delta) / L with v = vx / cos(beta) the CoM speed; beta = atan(lr tan(delta) / L).
Slip kinematic_slip(const VehicleParams& p, double vx, double steer) {
  const double tan_steer = std::tan(steer);
  return {std::atan(p.lr * tan_steer / p.wheelbase()), vx * tan_steer / p.wheelbase()};
}

Slip blend(const Slip& kinematic, const Slip& dynamic, double w) {
  return {(1 - w) * kinematic.beta + w * dynamic.beta, (1 - w) * kinematic.yaw_rate + w * dynamic.yaw_rate};
}

// Eq. 19, first two lines: beta dot and psi double dot with two tyres per axle. Only called where
// vx >= kinematic_below - kBlendWidth / 2 > 0, so the divisions by vx are safe.
// The paper prints l_f inside the rear-axle bracket; the rear tyre's slip angle is
// -beta + l_r psi_dot / v_x (the rear axle is l_r behind the CoM), which is what we use: only then does
// the steady state give R = (L + K v^2) / delta and tend to the kinematic L / delta as v -> 0.
Slip eq19_rates(const VehicleParams& p, double vx, double steer, const Slip& s) {
  const double front_slip = steer - s.beta - p.lf * s.yaw_rate / vx;
  const double rear_slip = -s.beta + p.lr * s.yaw_rate / vx;
  const double front_force = kTyresPerAxle * p.cornering_stiffness_front * front_slip;
  const double rear_force = kTyresPerAxle * p.cornering_stiffness_rear * rear_slip;
  return {(front_force + rear_force) / (p.mass * vx) - s.yaw_rate,
          (p.lf * front_force - p.lr * rear_force) / p.yaw_inertia};
}

// The states integrated by RK4. beta and yaw_rate here are Eq. 19's own states, not necessarily the
// motion's (they differ inside the blend band).
struct Continuous {
  double x = 0, y = 0, yaw = 0, vx = 0;
  Slip dyn;
};

Continuous add_scaled(const Continuous& a, const Continuous& d, double h) {
  return {a.x + h * d.x,
          a.y + h * d.y,
          a.yaw + h * d.yaw,
          a.vx + h * d.vx,
          {a.dyn.beta + h * d.dyn.beta, a.dyn.yaw_rate + h * d.dyn.yaw_rate}};
}

// Exact decay factor of a first-order lag over dt; a zero time constant follows the command at once.
double lag_factor(double dt, double time_constant) { return time_constant > 0 ? std::exp(-dt / time_constant) : 0.0; }

double understeer_gradient(const VehicleParams& p) {
  return p.mass / p.wheelbase() *
         (p.lr / (kTyresPerAxle * p.cornering_stiffness_front) - p.lf / (kTyresPerAxle * p.cornering_stiffness_rear));
}

}  // namespace

void read_vehicle_params(const YamlReader& y, const YAML::Node& n, VehicleParams& p) {
  YamlMap m(y, n, "vehicle");
  // Ranges: what a road vehicle from a small car to a loaded truck can have.
  m.number("cornering_stiffness_front", p.cornering_stiffness_front, 1e3, 1e6)
      .number("cornering_stiffness_rear", p.cornering_stiffness_rear, 1e3, 1e6)
      .number("lf", p.lf, 0.0, 10.0)
      .number("lr", p.lr, 0.0, 10.0)
      .number("yaw_inertia", p.yaw_inertia, 100.0, 1e6)
      .number("mass", p.mass, 100.0, 1e5)
      .number("steering_ratio", p.steering_ratio, 1.0, 50.0)
      .number("wheel_radius", p.wheel_radius, 0.1, 2.0)
      .number("track_width", p.track_width, 0.5, 4.0)
      .number("max_steer", p.max_steer, 0.01, 1.2)  // below pi/2, where tan(delta) of the kinematic model blows up
      .number("max_steer_rate", p.max_steer_rate, 0.01, 10.0)
      .number("steer_time_constant", p.steer_time_constant, 0.0, 2.0)
      .number("max_accel", p.max_accel, 0.1, 20.0)
      .number("max_decel", p.max_decel, 0.1, 20.0)
      .number("accel_time_constant", p.accel_time_constant, 0.0, 2.0)
      .number("max_speed", p.max_speed, 0.5, 100.0)
      .number("kinematic_below", p.kinematic_below, kBlendWidth, 10.0)  // keeps Eq. 19 away from vx = 0
      .integer("step_ns", p.step_ns, kMinStepNs, kMaxStepNs)
      .done();
  // The simulation samples controller and sensors on whole milliseconds: they must fall on steps.
  if (kMaxStepNs % p.step_ns != 0) y.fail(n["step_ns"], "step_ns must divide 1 ms (1000000) evenly");

  if (p.wheelbase() <= 0) y.fail(n["lf"] ? n["lf"] : n["lr"] ? n["lr"] : n, "lf + lr (the wheelbase) must be > 0");
  const double k = understeer_gradient(p);
  if (k < 0) {
    const double critical = std::sqrt(-p.wheelbase() / k);
    if (p.max_speed >= critical) {
      std::ostringstream msg;
      msg << "max_speed = " << p.max_speed << " m/s is not below the critical speed " << critical
          << " m/s of this oversteering vehicle (understeer gradient K = " << k
          << " rad s^2/m < 0 because lf C_f > lr C_r): Eq. 19 is unstable there; lower max_speed";
      y.fail(n["max_speed"] ? n["max_speed"] : n, msg.str());
    }
  }
}

VehicleParams load_vehicle_params(const std::string& path) {
  const YamlReader yaml = YamlReader::open(path);
  VehicleParams params;
  if (yaml.root().IsNull()) return params;  // a file of comments only: all defaults
  read_vehicle_params(yaml, yaml.root(), params);
  return params;
}

VehicleModel::VehicleModel(const VehicleParams& params, const VehicleState& initial)
    : params_(params), state_(initial) {
  // Guards against parameters built in code without read_vehicle_params: these would divide by zero.
  if (params_.step_ns <= 0 || params_.step_ns > kMaxStepNs)
    throw std::invalid_argument("VehicleParams::step_ns must be in (0, 1 ms]");
  if (params_.wheelbase() <= 0 || params_.mass <= 0 || params_.yaw_inertia <= 0)
    throw std::invalid_argument("VehicleParams: wheelbase, mass and yaw_inertia must be > 0");
  if (params_.kinematic_below < kBlendWidth)
    throw std::invalid_argument("VehicleParams::kinematic_below must be >= 1 m/s (Eq. 19 divides by v_x)");
  state_.vx = std::clamp(state_.vx, 0.0, params_.max_speed);
}

VehicleState VehicleModel::state_at(const VehicleParams& params, const Pose2d& rear_axle, double speed) {
  VehicleState s;
  s.x = rear_axle.x + params.lr * std::cos(rear_axle.yaw);
  s.y = rear_axle.y + params.lr * std::sin(rear_axle.yaw);
  s.yaw = rear_axle.yaw;
  s.vx = std::clamp(speed, 0.0, params.max_speed);
  return s;  // beta = yaw_rate = 0 is the steady state of both models with the wheels straight
}

// One step of params.step_ns.
//
// Actuators first, exactly: the lags are exponentials, then the rate and range limits. Within the step
// the reached steer and acceleration are taken as linear in time between their start and end values.
//
// Then RK4 on the CoM pose (Eq. 19's x dot, y dot with psi dot), v_x (dv_x/dt = reached acceleration) and
// Eq. 19's beta, yaw_rate. The motion uses beta, yaw_rate blended between the kinematic bicycle and Eq. 19
// with the weight w(v_x) (0 below kinematic_below - 0.5, 1 above kinematic_below + 0.5).
//
// Low-speed switch: VehicleState stores the blended (actually driven) beta and yaw_rate, so the wheel
// speeds and ground truth match the motion. Eq. 19's own states are recovered from them at the start of
// each step (dyn = (blended - (1 - w) kin) / w, exact algebra) and integrated whenever w > 0; while w is
// (nearly) 0 they are reset to the kinematic values. Speeding up, Eq. 19 therefore starts from the
// kinematic state, and slowing down its influence fades out linearly: the motion never jumps.
void VehicleModel::step(const VehicleCommand& command) {
  if (!std::isfinite(command.steer) || !std::isfinite(command.accel))
    throw std::invalid_argument("VehicleModel::step: the command is not finite");
  const VehicleParams& p = params_;
  const double dt = double(p.step_ns) / kNsPerS;

  // Steering actuator: first-order lag towards the (clamped) command, rate- and range-limited.
  const double steer_cmd = std::clamp(command.steer, -p.max_steer, p.max_steer);
  const double steer_lagged = steer_cmd + (state_.steer - steer_cmd) * lag_factor(dt, p.steer_time_constant);
  const double max_change = p.max_steer_rate * dt;
  const double steer0 = state_.steer;
  const double steer1 =
      std::clamp(steer0 + std::clamp(steer_lagged - steer0, -max_change, max_change), -p.max_steer, p.max_steer);
  // Drive and brakes: first-order lag towards the clamped command.
  const double accel_cmd = std::clamp(command.accel, -p.max_decel, p.max_accel);
  const double accel0 = state_.accel;
  const double accel1 =
      std::clamp(accel_cmd + (accel0 - accel_cmd) * lag_factor(dt, p.accel_time_constant), -p.max_decel, p.max_accel);

  auto recover_dynamic = [&](const VehicleState& s) {
    const double w = dynamic_weight(p, s.vx);
    const Slip kin = kinematic_slip(p, s.vx, s.steer);
    if (w < kNegligibleWeight) return kin;
    return Slip{(s.beta - (1 - w) * kin.beta) / w, (s.yaw_rate - (1 - w) * kin.yaw_rate) / w};
  };

  auto derivative = [&](const Continuous& c, double fraction) {
    const double steer = steer0 + (steer1 - steer0) * fraction;
    const double vx = std::max(c.vx, 0.0);  // v_x may dip below 0 inside a step that ends in a stop
    const double w = dynamic_weight(p, vx);
    const Slip kin = kinematic_slip(p, vx, steer);
    const Slip motion = w > 0 ? blend(kin, c.dyn, w) : kin;
    const double lateral = vx * std::tan(motion.beta);
    Continuous d;
    // Eq. 19, last two lines.
    d.x = vx * std::cos(c.yaw) - lateral * std::sin(c.yaw);
    d.y = vx * std::sin(c.yaw) + lateral * std::cos(c.yaw);
    d.yaw = motion.yaw_rate;
    d.vx = accel0 + (accel1 - accel0) * fraction;
    if (w > 0) d.dyn = eq19_rates(p, vx, steer, c.dyn);  // else: reset at the end of the step anyway
    return d;
  };

  const Continuous c0{state_.x, state_.y, state_.yaw, state_.vx, recover_dynamic(state_)};
  const Continuous k1 = derivative(c0, 0.0);
  const Continuous k2 = derivative(add_scaled(c0, k1, dt / 2), 0.5);
  const Continuous k3 = derivative(add_scaled(c0, k2, dt / 2), 0.5);
  const Continuous k4 = derivative(add_scaled(c0, k3, dt), 1.0);
  Continuous c1 = add_scaled(c0, k1, dt / 6);
  c1 = add_scaled(c1, k2, dt / 3);
  c1 = add_scaled(c1, k3, dt / 3);
  c1 = add_scaled(c1, k4, dt / 6);

  VehicleState next;
  next.x = c1.x;
  next.y = c1.y;
  next.yaw = wrap_angle(c1.yaw);
  next.steer = steer1;
  next.accel = accel1;
  // No reversing and no speeding: a standing car's brakes hold it, they do not push it backwards.
  next.vx = std::clamp(c1.vx, 0.0, p.max_speed);
  if (next.vx <= 0) next.accel = std::max(next.accel, 0.0);
  if (next.vx >= p.max_speed) next.accel = std::min(next.accel, 0.0);
  const double w = dynamic_weight(p, next.vx);
  const Slip kin = kinematic_slip(p, next.vx, next.steer);
  const Slip motion = w > 0 ? blend(kin, c1.dyn, w) : kin;
  next.beta = motion.beta;
  next.yaw_rate = motion.yaw_rate;
  state_ = next;
}

void VehicleModel::place(const Pose2d& rear_axle) {
  const VehicleState at = state_at(params_, rear_axle, state_.vx);
  state_.x = at.x;
  state_.y = at.y;
  state_.yaw = at.yaw;
}

Pose2d VehicleModel::rear_axle_pose() const {
  return {state_.x - params_.lr * std::cos(state_.yaw), state_.y - params_.lr * std::sin(state_.yaw), state_.yaw};
}

// Rigid body: the CoM moves at (vx, vx tan(beta)) in the body frame (Eq. 19's x dot, y dot) and a point r
// from it at that plus yaw_rate x r; each wheel reports that velocity along its own heading. The state's
// beta and yaw_rate are those the body moves with (blended at low speed), see step().
std::array<double, 4> VehicleModel::wheel_speeds() const {
  const Slip m{state_.beta, state_.yaw_rate};
  const double vx = state_.vx, vy = vx * std::tan(m.beta);
  const double half_track = params_.track_width / 2;
  auto along = [&](double px, double py, double heading) {
    const double wx = vx - m.yaw_rate * py, wy = vy + m.yaw_rate * px;
    return wx * std::cos(heading) + wy * std::sin(heading);
  };
  return {along(params_.lf, half_track, state_.steer), along(params_.lf, -half_track, state_.steer),
          along(-params_.lr, half_track, 0.0), along(-params_.lr, -half_track, 0.0)};
}

double steady_state_radius(const VehicleParams& params, double speed, double steer) {
  if (steer == 0) return std::numeric_limits<double>::infinity();
  return (params.wheelbase() + understeer_gradient(params) * speed * speed) / steer;
}

}  // namespace lidarloop
