#include "localizer/gps_step_detector.hpp"

#include <algorithm>
#include <cmath>

#include "common/units.hpp"

namespace lidarloop {

double GpsStepDetector::noise_sigma_m() const {
  return std::sqrt(std::max(noise_variance_, p_.min_noise_sigma_m * p_.min_noise_sigma_m));
}

void GpsStepDetector::shift(const Eigen::Vector2d& delta) {
  if (level_) *level_ += delta;
  if (last_) *last_ += delta;
}

bool GpsStepDetector::step(int64_t t_ns, const Eigen::Vector2d& innovation) {
  if (!level_ || !innovation.allFinite()) {
    if (innovation.allFinite()) level_ = last_ = innovation;
    last_ns_ = t_ns;
    return false;
  }
  // The distance from the level is a fix's white noise plus the level's own lag. noise_variance_ learns
  // the variance of the change between two fixes, twice the white variance: the margin covers the lag.
  const double sigma = noise_sigma_m();
  const Eigen::Vector2d d = innovation - *level_;
  if (d.squaredNorm() / (sigma * sigma) > p_.step_gate) return true;
  const double dt = std::max(0.0, double(t_ns - last_ns_) / kNsPerS);
  const double w = 1.0 - std::exp(-dt / p_.level_tau_s);
  *level_ += w * d;
  const Eigen::Vector2d change = innovation - *last_;
  // A plain mean over the first samples, then the same time constant as the level.
  const double w_noise = std::max(w, 1.0 / double(++noise_samples_));
  noise_variance_ += w_noise * (0.5 * change.squaredNorm() - noise_variance_);  // per axis: half the norm^2
  last_ = innovation;
  last_ns_ = t_ns;
  return false;
}

}  // namespace lidarloop
