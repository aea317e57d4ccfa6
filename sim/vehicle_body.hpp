#pragma once
// The ego's sprung mass on its suspension: heave, pitch and roll as three decoupled, linear
// spring-dampers (the half-car and roll models of Gillespie, Fundamentals of Vehicle Dynamics, SAE
// 1992, ch. 5 and 8), relative to the ground plane under the wheels (rest_on_ground), which stays the
// vehicle frame and the truth. Two things move the body:
//  - the specific force at the centre of mass, i.e. Eq. 19's acceleration plus gravity along the
//    tilted ground plane: braking dives the nose, a left turn rolls the body to the right side down
//    (left side up), grade and crown lean it downhill. At steady state the body sits at the static
//    deflection of its springs, m f h_cg / K (pitch: -m f_x h_cg / K_pitch, roll: m f_y h_cg / K_roll);
//    with K from the pitch and roll gradients this is gradient * f / g.
//  - the road: the ground plane's height (at the centre of mass), pitch and roll are the base the
//    springs and dampers are attached to, so grade, hills and roughness reach the body filtered by
//    the suspension (above ~2 Hz hardly at all) instead of rigidly.
// Each mode is q'' = -w^2 (q - g - e) - 2 z w (q' - g'), with q the body's absolute coordinate, g the
// ground plane's and e the static deflection; integrated by semi-implicit Euler at the vehicle's
// 1 ms step (w dt < 0.02: stable and accurate; the steady state is exact).
//
// Scenario section `body` (keys as the fields below):
//   rigid                    false   true: no suspension, the body is the ground plane (the `ideal` profile)
//   heave_frequency_hz       1.2     ride (bounce) natural frequency
//   heave_damping_ratio      0.3
//   pitch_frequency_hz       1.4
//   pitch_damping_ratio      0.3
//   pitch_gradient_deg_per_g 2.0     pitch per g of longitudinal specific force
//   roll_frequency_hz        1.5
//   roll_damping_ratio       0.3
//   roll_gradient_deg_per_g  5.0     roll per g of lateral specific force
//   cg_height_m              0.7     centre of mass above the ground (the pivot; sets K from a gradient)
#include <Eigen/Core>

#include "common/units.hpp"
#include "common/vehicle_messages.hpp"
#include "common/yaml_reader.hpp"
#include "sim/realism.hpp"
#include "sim/vehicle_model.hpp"

namespace lidarloop {

struct BodyConfig {
  bool rigid = false;
  // Gillespie ch. 5: passenger-car ride frequencies are 1-1.5 Hz; the middle of that range.
  double heave_frequency_hz = 1.2;
  // Gillespie ch. 5: modern passenger cars have damping ratios of 0.2-0.4; the middle of that range.
  double heave_damping_ratio = 0.3;
  // Assumption: pitch a little stiffer than bounce (the rear is sprung stiffer than the front,
  // Gillespie ch. 5, Olley's flat-ride rule), still within 1-1.5 Hz.
  double pitch_frequency_hz = 1.4;
  double pitch_damping_ratio = 0.3;  // Gillespie ch. 5: 0.2-0.4
  // Assumption (no sourced figure found): 2 deg/g, i.e. 1 deg of dive at 0.5 g of braking.
  double pitch_gradient_deg_per_g = 2.0;
  // Assumption: roll modes of passenger cars sit a little above bounce; within 1-2 Hz.
  double roll_frequency_hz = 1.5;
  double roll_damping_ratio = 0.3;  // Gillespie ch. 5: 0.2-0.4
  // Gillespie ch. 8: passenger cars roll 3-7 deg/g; the middle of that range for Table I's 2300 kg
  // SUV-class car.
  double roll_gradient_deg_per_g = 5.0;
  // NHTSA rollover ratings: SUVs have a static stability factor T / (2 h) of about 1.1-1.2; with the
  // 1.6 m track that is h ~ 0.7 m.
  double cg_height_m = 0.7;

  // Spring rates of the sprung mass `mass` that give these gradients: K = m g h / gradient, N m/rad.
  double pitch_stiffness(double mass) const;
  double roll_stiffness(double mass) const;
};

// ideal: rigid (the vehicle frame as before: no pitch, roll or heave relative to the ground);
// typical: BodyConfig{}; harsh: worn dampers and soft springs (see the .cpp).
BodyConfig body_config_for(Realism realism);

// Reads overrides of the scenario section `body`; file:line:col on errors.
void read_body_config(const YamlReader& yaml, const YAML::Node& node, BodyConfig& config);

// The ground plane under the wheels, where the body's springs are attached: its height below the
// centre of mass, its pitch and roll (conventions of BodyAttitude), in the local frame.
struct GroundPlane {
  double z = 0, pitch = 0, roll = 0;
};
// From rest_on_ground's pose and the centre of mass's distance ahead of the rear axle.
GroundPlane ground_plane(const Eigen::Isometry3d& ground_pose, double cg_ahead_of_rear_axle);

// The centre of mass's acceleration in the vehicle frame (x forward, y left) between two states
// of Eq. 19 `dt` apart: dv_x/dt, and v_x (yaw rate + d beta/dt) sideways.
Eigen::Vector2d planar_acceleration(const VehicleState& before, const VehicleState& after, double dt);

class VehicleBody {
 public:
  // At rest on `ground` (the equilibrium for no acceleration). `params` gives the centre of mass.
  VehicleBody(const BodyConfig& config, const VehicleParams& params, const GroundPlane& ground);

  // Advances by `dt` under the acceleration `accel` (vehicle frame) with the ground plane now at `ground`.
  void step(double dt, const Eigen::Vector2d& accel, const GroundPlane& ground);

  // The car set down on another ground plane (a kidnap of the car): the body keeps its attitude
  // relative to the ground and its rates, so the new ground's height and slope are no bump.
  void set_down(const GroundPlane& ground);

  // Relative to the ground plane; all zero (and pivot set) when rigid.
  const BodyAttitude& attitude() const { return attitude_; }
  const BodyConfig& config() const { return config_; }

 private:
  struct Mode {
    double q = 0, rate = 0;  // absolute coordinate and its rate
  };
  BodyConfig config_;
  GroundPlane ground_;
  Mode heave_, pitch_, roll_;
  BodyAttitude attitude_;
};

}  // namespace lidarloop
