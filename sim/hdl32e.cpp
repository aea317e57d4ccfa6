#include "sim/hdl32e.hpp"

#include <cmath>

#include "common/units.hpp"

namespace lidarloop {

std::array<double, kHdl32eLasers> Hdl32eConfig::default_elevations() {
  std::array<double, kHdl32eLasers> e{};
  // 4/3 deg steps rounded to 0.01 deg, as the manual lists them and as the drivers' HDL-32E
  // calibration holds them (vert_correction in the ROS driver's 32db.yaml and @foxglove/velodyne-cloud's
  // 32db.json is -30.67 deg, not -30.6667): a driver places points with these angles.
  for (int ring = 0; ring < kHdl32eLasers; ++ring) e[ring] = std::round((4.0 * ring - 92.0) / 3.0 * 100.0) / 100.0;
  return e;
}

std::array<int, kHdl32eLasers> Hdl32eConfig::default_firing_order() {
  std::array<int, kHdl32eLasers> order{};
  for (int k = 0; k < kHdl32eLasers / 2; ++k) {
    order[2 * k] = k;                          // lower bank: -30.67 ... -10.67
    order[2 * k + 1] = k + kHdl32eLasers / 2;  // upper bank: -9.33 ... +10.67
  }
  return order;
}

Eigen::Isometry3d Hdl32eConfig::mount() const {
  constexpr double deg = M_PI / 180;
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translate(mount_xyz);
  m.rotate(Eigen::AngleAxisd(mount_rpy_deg.z() * deg, Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(mount_rpy_deg.y() * deg, Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(mount_rpy_deg.x() * deg, Eigen::Vector3d::UnitX()));
  return m;
}

Hdl32eCalibration Hdl32eConfig::calibration() const {
  Hdl32eCalibration c;
  for (size_t slot = 0; slot < size_t(kHdl32eLasers); ++slot) {
    const double elevation = elevation_deg[size_t(firing_order[slot])] * kDeg;
    c.ring[slot] = uint16_t(firing_order[slot]);
    c.cos_elevation[slot] = std::cos(elevation);
    c.sin_elevation[slot] = std::sin(elevation);
  }
  c.firing_period_ns = firing_period_ns;
  c.cycle_period_ns = cycle_period_ns();
  return c;
}

Hdl32eConfig hdl32e_config_for(Realism realism) {
  Hdl32eConfig c;
  switch (realism) {
    case Realism::ideal:
      c.laser_range_bias_sigma_m = 0;
      c.laser_intensity_offset_sigma = 0;
      c.dropout_probability = 0;
      c.mixed_returns = false;
      break;
    case Realism::typical:
      break;
    case Realism::harsh:
      // A poorly calibrated unit: assumptions, about three times the typical spreads (Blensor's
      // default per-laser range bias sigma, 7.8 cm, is larger still).
      c.laser_range_bias_sigma_m = 0.03;
      c.laser_intensity_offset_sigma = 5.0;
      c.laser_gain_spread = 0.15;
      c.dropout_probability = 0.01;
      break;
  }
  return c;
}

void read_hdl32e_config(const YamlReader& y, const YAML::Node& n, Hdl32eConfig& c) {
  YamlMap m(y, n, "lidar");
  if (const YAML::Node e = m["elevation_deg"]) {
    if (!e.IsSequence() || e.size() != kHdl32eLasers) y.fail(e, "elevation_deg must list 32 elevations");
    for (int i = 0; i < kHdl32eLasers; ++i) c.elevation_deg[i] = y.number_in(e[i], "elevation_deg", -90.0, 90.0);
  }
  if (const YAML::Node o = m["firing_order"]) {
    if (!o.IsSequence() || o.size() != kHdl32eLasers) y.fail(o, "firing_order must list 32 ring indices");
    std::array<bool, kHdl32eLasers> seen{};
    for (int i = 0; i < kHdl32eLasers; ++i) {
      c.firing_order[i] = int(y.integer_in(o[i], "firing_order", 0, kHdl32eLasers - 1));
      if (seen[c.firing_order[i]]) y.fail(o[i], "firing_order lists a ring twice");
      seen[c.firing_order[i]] = true;
    }
  }
  m.integer("firing_period_ns", c.firing_period_ns, 100, 100000)
      .integer("slots_per_cycle", c.slots_per_cycle, kHdl32eLasers, 1000)
      .number("rotation_hz", c.rotation_hz, 5.0, 20.0)
      .number("scan_start_yaw_deg", c.scan_start_yaw_deg, -360.0, 360.0)
      .number("min_range_m", c.min_range_m, 0.0, 10.0)
      .number("max_range_m", c.max_range_m, 1.0, 300.0)
      .number("range_resolution_m", c.range_resolution_m, 0.0, 0.1)
      .number("range_noise_m", c.range_noise_m, 0.0, 1.0)
      .number("dark_target_reflectivity", c.dark_target_reflectivity, 0.001, 1.0)
      .number("dark_target_range_m", c.dark_target_range_m, 1.0, 1000.0)
      .number("detection_incidence_exponent", c.detection_incidence_exponent, 0.0, 4.0)
      .number("detection_softness", c.detection_softness, 0.0, 2.0)
      .number("max_incidence_deg", c.max_incidence_deg, 0.0, 90.0)
      .number("intensity_incidence_exponent", c.intensity_incidence_exponent, 0.0, 4.0)
      .number("intensity_reference_range_m", c.intensity_reference_range_m, 0.1, 1000.0)
      .number("intensity_range_exponent", c.intensity_range_exponent, 0.0, 4.0)
      .number("intensity_noise", c.intensity_noise, 0.0, 50.0)
      .number("laser_gain_spread", c.laser_gain_spread, 0.0, 0.5)
      .integer("unit_serial", c.unit_serial, 0, uint64_t(1) << 40)
      .number("laser_range_bias_sigma_m", c.laser_range_bias_sigma_m, 0.0, 0.5)
      .number("laser_intensity_offset_sigma", c.laser_intensity_offset_sigma, 0.0, 50.0)
      .number("dropout_probability", c.dropout_probability, 0.0, 1.0)
      .boolean("mixed_returns", c.mixed_returns)
      .number("beam_divergence_mrad", c.beam_divergence_mrad, 0.0, 50.0)
      .number("mixed_edge_step_m", c.mixed_edge_step_m, 0.001, 10.0)
      .number("pulse_length_m", c.pulse_length_m, 0.0, 10.0)
      .vec3("mount_xyz", c.mount_xyz)
      .vec3("mount_rpy_deg", c.mount_rpy_deg)
      .boolean("motion_distortion", c.motion_distortion)
      .integer("cycles_per_actor_update", c.cycles_per_actor_update, 1, 10000)
      .done();
  if (c.min_range_m >= c.max_range_m) y.fail(n, "min_range_m must be below max_range_m");
}

}  // namespace lidarloop
