#pragma once
// How the sensors truly sit on the car against what the car's configuration says (scenario section
// `mount_error`). The scenario's `lidar:` mount_xyz / mount_rpy_deg and `gps:` antenna_xyz are the
// nominal values: what the calibration sheet says, and all the localizer is given. The true mount
// differs from them by one draw per run, fixed by the scenario seed (its own random stream): the
// residual of the calibration the car went through, not something the localizer can see.
//
// Keys (1 sigma per axis of the true mount against the nominal; `typical` defaults):
//   lidar_rotation_deg: [roll, pitch, yaw]  0.1 deg each: a target-based end-of-line calibration, "within
//                                           0.1 degree and 3 mm levels of precision" (arXiv 2008.10542)
//   lidar_translation_m: [x, y, z]          0.003 m each (the same source)
//   gps_antenna_m: [x, y, z]                0.01 m each: the antenna's lever arm taken with a tape
//                                           measure from the rear axle (assumption)
// ideal: all zero (the sensors sit exactly where the configuration says). harsh: a targetless
// calibration, "rotation and translation errors less than 0.04 [rad] and 0.1 [m]" (arXiv 1905.04912),
// the bounds read as 2 sigma (assumption): 0.02 rad (1.15 deg) and 0.05 m; the antenna measured
// roughly, 0.05 m (assumption).
#include <cstdint>

#include <Eigen/Core>

#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "sim/gps_model.hpp"
#include "sim/hdl32e.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

struct MountErrorConfig {
  Eigen::Vector3d lidar_rotation_sigma_rad = Eigen::Vector3d::Constant(0.1 * kDeg);
  Eigen::Vector3d lidar_translation_sigma_m = Eigen::Vector3d::Constant(0.003);
  Eigen::Vector3d gps_antenna_sigma_m = Eigen::Vector3d::Constant(0.01);
};

MountErrorConfig mount_error_config_for(Realism realism);
// Overrides from a `mount_error:` mapping; unknown keys and bad values are file:line:col errors.
void read_mount_error(const YamlReader& y, const YAML::Node& node, MountErrorConfig& config);

// One run's draw: the true mount minus the nominal one.
struct MountDraw {
  Eigen::Vector3d lidar_rpy_rad = Eigen::Vector3d::Zero();  // added to the nominal roll, pitch, yaw
  Eigen::Vector3d lidar_xyz_m = Eigen::Vector3d::Zero();    // added to the nominal position (vehicle frame)
  Eigen::Vector3d gps_antenna_m = Eigen::Vector3d::Zero();  // added to the nominal lever arm (vehicle frame)
};

// The draw of the run with this scenario seed: the same seed gives the same draw.
MountDraw draw_mount_error(const MountErrorConfig& config, uint64_t scenario_seed);

// The sensors as they truly are: the nominal configuration moved by the draw.
Hdl32eConfig with_true_mount(Hdl32eConfig nominal, const MountDraw& draw);
GpsConfig with_true_antenna(GpsConfig nominal, const MountDraw& draw);

}  // namespace lidarloop
