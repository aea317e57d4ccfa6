#pragma once
// Velodyne HDL-32E: beam geometry, firing timing and return model parameters, with the datasheet's
// values as defaults. All of it can be overridden from YAML (`lidar:` in a scenario).
#include <array>
#include <cstdint>

#include <Eigen/Geometry>

#include "common/hdl32e_driver.hpp"
#include "common/yaml_reader.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

constexpr int kHdl32eLasers = 32;

struct Hdl32eConfig {
  // Elevation of each laser by ring (0 = lowest): -30.67 deg to +10.67 deg in 4/3 deg steps, rounded to
  // 0.01 deg as in the HDL-32E calibration the drivers use.
  std::array<double, kHdl32eLasers> elevation_deg = default_elevations();
  // The ring fired in each of the 32 firing slots of a cycle: the lower and upper banks alternate,
  // -30.67, -9.33, -29.33, -8.00, ..., -10.67, +10.67. Slot k is also channel k of a data block: the
  // drivers' HDL-32E calibration lists laser_id 0-31 in this order (32db.yaml in the ROS driver,
  // 32db.json in @foxglove/velodyne-cloud), and both read channel j of a block as laser j.
  std::array<int, kHdl32eLasers> firing_order = default_firing_order();
  int64_t firing_period_ns = 1152;  // one laser every 1.152 us
  int slots_per_cycle = 40;         // 32 firings + 8 idle slots = 46.08 us per cycle
  double rotation_hz = 10.0;        // 5-20 Hz
  double scan_start_yaw_deg = 180;  // where a scan begins (and the previous one ends): behind the car

  double min_range_m = 1.0;
  double max_range_m = 100.0;
  double range_resolution_m = 0.002;  // 2 mm quantisation
  double range_noise_m = 0.02;        // 1 sigma

  // Detection: received power ~ reflectivity * cos(incidence)^detection_incidence_exponent / range^2;
  // a target of dark_target_reflectivity at dark_target_range_m is detected half the time.
  double dark_target_reflectivity = 0.10;
  double dark_target_range_m = 70.0;
  double detection_incidence_exponent = 0.5;
  double detection_softness = 0.15;  // width of the detection ramp in log power
  double max_incidence_deg = 87.0;   // grazing returns beyond this are lost
  // Intensity: 100 * reflectivity * cos(incidence)^intensity_incidence_exponent * laser gain
  //            * min(1, intensity_reference_range_m / range)^intensity_range_exponent + noise.
  double intensity_incidence_exponent = 0.5;
  double intensity_reference_range_m = 10.0;
  double intensity_range_exponent = 0.25;
  double intensity_noise = 1.5;     // counts, 1 sigma
  double laser_gain_spread = 0.08;  // per-laser gains uniform in 1 +- spread, fixed by the unit's serial
  uint64_t unit_serial = 1;

  // Per-laser faults left after the factory calibration, fixed by the unit's serial like the gains
  // (each laser draws once from a zero-mean normal of this sigma). A range bias shifts every range of
  // a laser; an intensity offset adds counts to every diffuse return of a laser.
  // Range bias 1 cm: assumption, within the datasheet's accuracy (<2 cm) and of the size that in-situ
  // recalibration removes (Chen & Chien 2012, HDL-64E: factory parameters leave layered ring
  // misalignment; recalibration cut planar RMS error by up to 49 %).
  double laser_range_bias_sigma_m = 0.01;
  // Intensity offset 2 counts: assumption (the HDL-64E's calibration table carries per-laser intensity
  // corrections, Velodyne HDL-64E S3 manual; Levinson & Thrun 2010 calibrate per-beam remittance; the
  // HDL-32E ships none, so some spread remains).
  double laser_intensity_offset_sigma = 2.0;
  // Random dropouts: a firing returns nothing with this probability, whatever it hit. Most real ray
  // drop is dark or grazing surfaces (the detection model above); this is the remainder, 0.1 %:
  // assumption.
  double dropout_probability = 0.001;

  // Mixed returns at depth edges. The beam is not a line: its spot is a rectangle about 4 in wide by
  // 2 in tall at 100 ft (HDL-32E user manual, appendix D), 3.3 mrad horizontal divergence, wider than
  // the 2.9 mrad between a laser's firings at 10 Hz. Where the range jumps between two neighbouring
  // firings of a laser (a depth edge: the jump differs from the range trend on both sides by more than
  // mixed_edge_step_m), the spot may straddle both surfaces; the edge lies uniformly between the two
  // beam centres, the spot's fraction beyond it is the other surface's share, and when the two echoes
  // overlap in time (range difference below pulse_length_m) the sensor reports one range between
  // them, weighted by each surface's share of the received power.
  bool mixed_returns = true;
  double beam_divergence_mrad = 3.33;  // horizontal, full width (manual: 4 in at 100 ft)
  double mixed_edge_step_m = 0.05;     // assumption: below this a mix hides in the 2 cm range noise
  // 4 ns pulses (Velodyne, HDL-64E principles of operation; assumed the same for the HDL-32E) are
  // c * 4 ns / 2 = 0.6 m long in range: echoes farther apart than that are resolved, not merged.
  double pulse_length_m = 0.6;

  // Sensor pose in the vehicle frame (origin at the rear axle centre on the ground).
  Eigen::Vector3d mount_xyz{1.2, 0.0, 1.9};
  Eigen::Vector3d mount_rpy_deg{0.0, 0.0, 0.0};
  bool motion_distortion = true;  // cast each firing from the pose at its own time
  // Actor poses are keyframed every this many firing cycles (1.47 ms) and interpolated linearly in
  // between; raised automatically if a scan would need more keyframes than Embree allows.
  int cycles_per_actor_update = 32;

  int64_t cycle_period_ns() const { return firing_period_ns * slots_per_cycle; }
  int64_t scan_period_ns() const { return static_cast<int64_t>(1e9 / rotation_hz + 0.5); }
  // Full firing cycles in one revolution: 2170 at 10 Hz.
  int cycles_per_scan() const { return static_cast<int>(scan_period_ns() / cycle_period_ns()); }
  int64_t firing_time_ns(int cycle, int slot) const { return cycle * cycle_period_ns() + slot * firing_period_ns; }
  // How far the head turns between a cycle's azimuth reading (its first firing) and the middle of its
  // 32 firings: 15.5 slots, 0.064 deg at 10 Hz. Drivers place all 32 returns at the reading.
  double mean_firing_lag_deg() const {
    return 360.0 * rotation_hz * double(firing_period_ns) * 1e-9 * (kHdl32eLasers - 1) / 2.0;
  }
  Eigen::Isometry3d mount() const;
  // What a driver needs to decode this unit's blocks (its vertical angles and firing timing).
  Hdl32eCalibration calibration() const;

  static std::array<double, kHdl32eLasers> default_elevations();
  static std::array<int, kHdl32eLasers> default_firing_order();
};

// The sensor of a realism profile: typical = the defaults above (a factory-calibrated unit); ideal =
// no range biases, no intensity offsets, no random dropouts, no mixed returns (the sensor as it was
// before these faults were modelled); harsh = a poorly calibrated unit.
Hdl32eConfig hdl32e_config_for(Realism realism);

// Applies the overrides in a YAML mapping (keys as the field names) and validates the result.
void read_hdl32e_config(const YamlReader& yaml, const YAML::Node& node, Hdl32eConfig& config);

}  // namespace lidarloop
