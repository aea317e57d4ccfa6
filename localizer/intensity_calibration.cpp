#include "localizer/intensity_calibration.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop {

IntensityCalibration::IntensityCalibration(const IntensityCalibrationParams& params) : params_(params) {}

void IntensityCalibration::add(int ring, double reading, double map_mean, double weight) {
  if (!valid(ring) || !std::isfinite(reading) || !std::isfinite(map_mean) || !(weight > 0)) return;
  Sums& s = sums_[size_t(ring)];
  const double w = weight;
  s.n += w, s.x += w * map_mean, s.y += w * reading, s.xx += w * map_mean * map_mean, s.xy += w * map_mean * reading;
}

void IntensityCalibration::end_scan() {
  const double k = params_.prior_points, lo = params_.prior_dark, hi = params_.prior_bright;
  for (size_t r = 0; r < sums_.size(); ++r) {
    Sums& s = sums_[r];
    if (s.n == 0) continue;
    // The data and the prior's pseudo-returns (lo read lo, hi read hi) in one least-squares fit.
    const double n = s.n + 2 * k, x = s.x + k * (lo + hi), y = s.y + k * (lo + hi);
    const double xx = s.xx + k * (lo * lo + hi * hi), xy = s.xy + k * (lo * lo + hi * hi);
    const double det = n * xx - x * x;
    if (det > 0) {
      const double gain = std::clamp((n * xy - x * y) / det, params_.min_gain, params_.max_gain);
      fit_[r] = {gain, (y - gain * x) / n};
    }
    const double f = params_.forgetting;
    s = {s.n * f, s.x * f, s.y * f, s.xx * f, s.xy * f};
  }
}

double IntensityCalibration::correct(int ring, double reading) const {
  if (!params_.enabled || !valid(ring)) return reading;
  const Fit& f = fit_[size_t(ring)];
  return (reading - f.offset) / f.gain;
}

}  // namespace lidarloop
