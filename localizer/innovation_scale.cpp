#include "localizer/innovation_scale.hpp"

#include <algorithm>

#include <Eigen/Geometry>

namespace lidarloop {

void InnovationScale::add(const Eigen::Vector2d& innovation, const Eigen::Vector2d& prior_variance,
                          const Eigen::Vector2d& claimed_variance) {
  // A plain mean over the first observations, then exponential over the window.
  const double w = 1.0 / double(std::min(++samples_, p_.window));
  for (int a = 0; a < 2; ++a) {
    if (!(claimed_variance[a] > 0)) continue;
    const double excess = (innovation[a] * innovation[a] - prior_variance[a]) / claimed_variance[a];
    mean_excess_[a] += w * (excess - mean_excess_[a]);
  }
}

Eigen::Vector2d InnovationScale::scale() const { return mean_excess_.cwiseMax(1.0).cwiseMin(p_.max_scale); }

Eigen::Matrix2d scaled_along_across(const Eigen::Matrix2d& covariance, double yaw, const Eigen::Vector2d& scale) {
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  const Eigen::Matrix2d D = scale.cwiseSqrt().asDiagonal();
  return R * D * R.transpose() * covariance * R * D * R.transpose();
}

}  // namespace lidarloop
