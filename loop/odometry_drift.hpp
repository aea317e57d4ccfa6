#pragma once
// How far CAN odometry drifts from the truth: the wheel speeds and steering of a drive dead-reckoned with
// the localizer's own Eq. 19 predictor (as Localizer::on_can does), and over every stretch of a given
// length, the odometry's motion put on the true pose at the stretch's start and compared with the true
// pose at its end (the relative pose error of odometry evaluation, e.g. KITTI's). This is what the
// pose filter's process noise stands for (PoseFilterParams: position_per_sqrt_m, yaw_per_sqrt_m), so
// the figures say what it should be: an error that grows with the square root of the distance is a
// random walk (RMS / sqrt(length) the same at every length), one that grows with the distance itself a
// scale or offset error (RMS / length the same).
#include <cstddef>
#include <vector>

#include "common/vehicle_messages.hpp"
#include "localizer/pose_filter.hpp"

namespace lidarloop {

struct OdometryDrift {
  double length_m = 0;
  size_t stretches = 0;  // one starting every metre driven; they overlap
  double lateral_rms_m = 0, longitudinal_rms_m = 0, heading_rms_rad = 0;
};

// One result per length in `lengths_m` (no stretches if the drive is shorter). The truth sorted by stamp;
// the CAN frames in arrival order (out-of-order and non-finite frames are skipped, as the localizer
// does). `max_step_s`: the localizer's Euler step (LocalizerParams::max_prediction_step_s).
std::vector<OdometryDrift> odometry_drift(const std::vector<TruthSample>& truth, const std::vector<CanFrame>& can,
                                          const VehicleModelParams& vehicle, double max_step_s,
                                          const std::vector<double>& lengths_m);

}  // namespace lidarloop
