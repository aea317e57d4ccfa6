#pragma once
// Whether a localizer's map observations are as good as their covariances say, checked against the
// truth one observation at a time (the filter's NEES mixes them with the prediction and its process
// noise, which can hide an observation that claims too much). Each observation's error is taken in
// the car's axes at its own heading, against the truth's matching pose: the true pose turned by the
// drawn mount yaw, which is what a scan placed with the nominal mount measures. For an intensity
// observation, z = p + J (psi_prior - psi), the truth's side is p + J (psi_prior - psi_true).
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "common/map_observation.hpp"
#include "common/pose2d.hpp"

namespace lidarloop {

struct ObservationConsistency {
  // Per axis (along, across, heading): the observations that took it (finite variance) and the mean of
  // their squared error over their variance, 1 when honest (NaN without any).
  Eigen::Matrix<size_t, 3, 1> counts = Eigen::Matrix<size_t, 3, 1>::Zero();
  Eigen::Vector3d mean_nees = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Its RMS error per axis (m, m, rad), over the same observations.
  Eigen::Vector3d rms_error = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// `truth` sorted by stamp; observations outside its time range are left out. `mount_yaw_rad`: the true
// mount's yaw against the nominal one. A position axis whose sigma exceeds `informative_sigma_m` says
// next to nothing (the curbs' along a straight) and is left out.
ObservationConsistency observation_consistency(const std::vector<PoseStamped>& truth,
                                               const std::vector<MapObservation>& observations, double mount_yaw_rad,
                                               double informative_sigma_m);

}  // namespace lidarloop
