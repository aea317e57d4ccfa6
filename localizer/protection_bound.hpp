#pragma once
// Protection bounds (integrity): per scan, the lateral and longitudinal error the estimate exceeds with
// at most a stated probability. From the filter's covariance, in the estimate's own vehicle frame,
// times the two-sided normal quantile of that probability; widened by every observation the filter
// refused in the last moments (lost_detector.hpp), since the truth may be where it pointed. A bound is
// only as honest as the covariance is consistent: the scorer's NEES and misleading frames check both.
#include <deque>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"
#include "localizer/lost_detector.hpp"

namespace lidarloop {

struct IntegrityParams {
  // The probability the error stays within the bound, per axis and scan. 1 - 1e-4: one misleading
  // frame in ten thousand if the covariance is honest and the errors Gaussian.
  double probability = 0.9999;
};

// k with P(|N(0, 1)| <= k) = probability (3.89 for 0.9999). Throws std::invalid_argument outside (0, 1).
double normal_two_sided_quantile(double probability);

struct ProtectionBounds {
  double lateral_m = 0, longitudinal_m = 0;
};

// `covariance`: the filter's (x, y, psi) in the local frame; `pose`: the estimate.
ProtectionBounds protection_bounds(const Eigen::Matrix3d& covariance, const Pose2d& pose,
                                   const std::deque<Disagreement>& refused, const IntegrityParams& params);

}  // namespace lidarloop
