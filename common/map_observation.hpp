#pragma once
// A map observation as a localizer's filter took it in one scan (a curb or point-cloud match's pose,
// APS's position), kept so that its covariance can be checked against the truth
// (scoring/observation_consistency.hpp). It is of the matching pose: the car's as the nominal LiDAR
// mount places the scan (localizer/pose_filter.hpp). An intensity observation is z = p + J (psi_prior -
// psi): its x, y in `pose`, the prior's heading in pose.yaw, and J.
#include <cstdint>

#include <Eigen/Core>

#include "common/pose2d.hpp"

namespace lidarloop {

struct MapObservation {
  int64_t stamp_ns = 0;
  Pose2d pose;
  // In the car's axes at pose.yaw: along, across, heading. Infinite on an axis not taken (intensity's
  // heading always; along or across where APS said nothing).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  Eigen::Vector2d yaw_coupling = Eigen::Vector2d::Zero();  // J (local frame, m/rad); intensity only
};

// `covariance` (x, y, psi in the local frame) in the car's axes at `yaw`; an infinite heading variance
// stays as it is.
Eigen::Matrix3d in_car_axes(const Eigen::Matrix3d& covariance, double yaw);

}  // namespace lidarloop
