#pragma once
// An observation's noise, calibrated from its own innovations (covariance matching: Mehra, "On the
// identification of variances and adaptive Kalman filtering", IEEE TAC 1970). Over the observations
// the filter took, E[nu_a^2] = P_a + R_a on each axis a, so the mean of (nu_a^2 - P_a) / R_a is how many
// times larger the observation's true variance is than the one its matcher claims. APS, for one, claims
// the spread of Eq. 14's distribution, which its correlated cells make several times too narrow.
// The scale is learnt per axis of the car (along, across), never below 1 (a matcher is not trusted
// beyond its own claim), and applied to the next observations.
#include <Eigen/Core>

namespace lidarloop {

struct InnovationScaleParams {
  int window = 50;          // observations the running mean spans (an exponential one)
  double max_scale = 25.0;  // at most this many times the claimed variance
};

class InnovationScale {
 public:
  explicit InnovationScale(const InnovationScaleParams& params = {}) : p_(params) {}

  // One accepted observation: its innovation, the filter's and the observation's variance, each per
  // axis of the car (along, across).
  void add(const Eigen::Vector2d& innovation, const Eigen::Vector2d& prior_variance,
           const Eigen::Vector2d& claimed_variance);
  // The factor on each axis's claimed variance.
  Eigen::Vector2d scale() const;

 private:
  InnovationScaleParams p_;
  Eigen::Vector2d mean_excess_ = Eigen::Vector2d::Ones();  // starts at the matcher's word
  int samples_ = 0;
};

// `covariance` (local frame) with its variances along and across a car at `yaw` multiplied by `scale`.
Eigen::Matrix2d scaled_along_across(const Eigen::Matrix2d& covariance, double yaw, const Eigen::Vector2d& scale);

}  // namespace lidarloop
