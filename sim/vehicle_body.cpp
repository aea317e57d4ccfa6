#include "sim/vehicle_body.hpp"

#include <cmath>
#include <numbers>

#include "common/units.hpp"

namespace lidarloop {

namespace {

// Harsh: a car with worn dampers and soft (or heavily loaded) springs.
constexpr double kWornDampingRatio = 0.15;    // assumption: a worn damper keeps about half of 0.3
constexpr double kSoftRollGradient = 7.0;     // deg/g, the top of Gillespie ch. 8's 3-7 deg/g
constexpr double kSoftPitchGradient = 3.0;    // deg/g, assumption (1.5 times the typical 2 deg/g)
constexpr double kMaxFrequencyHz = 10.0;      // above any body mode; keeps w dt small at 1 ms
constexpr double kMaxGradientDegPerG = 30.0;  // far beyond any road car
constexpr double kMaxCgHeight = 3.0;          // m, a loaded truck

double omega(double hz) { return 2 * std::numbers::pi * hz; }

// One mode's acceleration: spring towards ground + deflection, damper on the rate relative to the ground's.
double mode_accel(double q, double rate, double hz, double zeta, double ground, double ground_rate, double deflection) {
  const double w = omega(hz);
  return -w * w * (q - ground - deflection) - 2 * zeta * w * (rate - ground_rate);
}

struct Deflection {
  double pitch = 0, roll = 0;
};

// The springs' static deflection under the specific force at the centre of mass (what an
// accelerometer there reads): the motion's acceleration minus gravity, in the tilted ground plane's
// axes (a nose-down plane pulls the car forward, a left-up plane pulls it to the left). The force acts
// h above the ground against the springs: braking (f_x < 0) dives the nose (pitch > 0), a leftward
// force lifts the left side (roll > 0). gradient * f / g = m f h / K.
Deflection static_deflection(const BodyConfig& c, const Eigen::Vector2d& accel, const GroundPlane& ground) {
  const double fx = accel.x() - kGravity * std::sin(ground.pitch);
  const double fy = accel.y() + kGravity * std::sin(ground.roll);
  return {-c.pitch_gradient_deg_per_g * kDeg * fx / kGravity, c.roll_gradient_deg_per_g * kDeg * fy / kGravity};
}

}  // namespace

double BodyConfig::pitch_stiffness(double mass) const {
  return mass * kGravity * cg_height_m / (pitch_gradient_deg_per_g * kDeg);
}

double BodyConfig::roll_stiffness(double mass) const {
  return mass * kGravity * cg_height_m / (roll_gradient_deg_per_g * kDeg);
}

BodyConfig body_config_for(Realism realism) {
  BodyConfig c;
  switch (realism) {
    case Realism::ideal:
      c.rigid = true;
      break;
    case Realism::typical:
      break;
    case Realism::harsh:
      c.heave_damping_ratio = c.pitch_damping_ratio = c.roll_damping_ratio = kWornDampingRatio;
      c.roll_gradient_deg_per_g = kSoftRollGradient;
      c.pitch_gradient_deg_per_g = kSoftPitchGradient;
      break;
  }
  return c;
}

void read_body_config(const YamlReader& y, const YAML::Node& n, BodyConfig& c) {
  YamlMap(y, n, "body")
      .boolean("rigid", c.rigid)
      .number("heave_frequency_hz", c.heave_frequency_hz, 0.1, kMaxFrequencyHz)
      .number("heave_damping_ratio", c.heave_damping_ratio, 0.01, 2.0)
      .number("pitch_frequency_hz", c.pitch_frequency_hz, 0.1, kMaxFrequencyHz)
      .number("pitch_damping_ratio", c.pitch_damping_ratio, 0.01, 2.0)
      .number("pitch_gradient_deg_per_g", c.pitch_gradient_deg_per_g, 0.01, kMaxGradientDegPerG)
      .number("roll_frequency_hz", c.roll_frequency_hz, 0.1, kMaxFrequencyHz)
      .number("roll_damping_ratio", c.roll_damping_ratio, 0.01, 2.0)
      .number("roll_gradient_deg_per_g", c.roll_gradient_deg_per_g, 0.01, kMaxGradientDegPerG)
      .number("cg_height_m", c.cg_height_m, 0.1, kMaxCgHeight)
      .done();
}

GroundPlane ground_plane(const Eigen::Isometry3d& ground_pose, double cg_ahead_of_rear_axle) {
  // rest_on_ground's rotation is Rz(yaw) Ry(pitch) Rx(roll): its third row is
  // (-sin pitch, cos pitch sin roll, cos pitch cos roll).
  const Eigen::Matrix3d r = ground_pose.linear();
  return {(ground_pose * Eigen::Vector3d(cg_ahead_of_rear_axle, 0, 0)).z(), std::asin(-r(2, 0)),
          std::atan2(r(2, 1), r(2, 2))};
}

Eigen::Vector2d planar_acceleration(const VehicleState& before, const VehicleState& after, double dt) {
  const double beta_rate = (after.beta - before.beta) / dt;
  return {(after.vx - before.vx) / dt, after.vx * (after.yaw_rate + beta_rate)};
}

VehicleBody::VehicleBody(const BodyConfig& config, const VehicleParams& params, const GroundPlane& ground)
    : config_(config), ground_(ground) {
  attitude_.pivot = {params.lr, 0, config.cg_height_m};
  if (config_.rigid) return;
  // At rest: each mode at its static deflection under gravity alone.
  const Deflection d = static_deflection(config_, Eigen::Vector2d::Zero(), ground);
  heave_ = {ground.z, 0};
  pitch_ = {ground.pitch + d.pitch, 0};
  roll_ = {ground.roll + d.roll, 0};
  attitude_.pitch = d.pitch;
  attitude_.roll = d.roll;
}

void VehicleBody::step(double dt, const Eigen::Vector2d& accel, const GroundPlane& ground) {
  if (config_.rigid || dt <= 0) return;
  const BodyConfig& c = config_;
  const Deflection d = static_deflection(c, accel, ground);
  const double z_rate = (ground.z - ground_.z) / dt, pitch_rate = (ground.pitch - ground_.pitch) / dt,
               roll_rate = (ground.roll - ground_.roll) / dt;
  // Semi-implicit Euler: rates first, then coordinates with the new rates.
  heave_.rate +=
      dt * mode_accel(heave_.q, heave_.rate, c.heave_frequency_hz, c.heave_damping_ratio, ground.z, z_rate, 0.0);
  pitch_.rate += dt * mode_accel(pitch_.q, pitch_.rate, c.pitch_frequency_hz, c.pitch_damping_ratio, ground.pitch,
                                 pitch_rate, d.pitch);
  roll_.rate +=
      dt * mode_accel(roll_.q, roll_.rate, c.roll_frequency_hz, c.roll_damping_ratio, ground.roll, roll_rate, d.roll);
  heave_.q += dt * heave_.rate;
  pitch_.q += dt * pitch_.rate;
  roll_.q += dt * roll_.rate;
  ground_ = ground;
  attitude_.heave = heave_.q - ground.z;
  attitude_.pitch = pitch_.q - ground.pitch;
  attitude_.roll = roll_.q - ground.roll;
}

void VehicleBody::set_down(const GroundPlane& ground) {
  if (config_.rigid) return;
  heave_.q += ground.z - ground_.z;
  pitch_.q += ground.pitch - ground_.pitch;
  roll_.q += ground.roll - ground_.roll;
  ground_ = ground;
}

}  // namespace lidarloop
