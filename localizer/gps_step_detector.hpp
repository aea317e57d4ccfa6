#pragma once
// Telling a GPS jump (multipath, a receiver re-acquiring) or a kidnapped filter from the low-cost GPS's
// ordinary error. That error is mostly a slowly wandering bias (Gauss-Markov, tau of minutes) plus a
// few decimetres of white noise, so one fix 3 m from the filter is nothing unusual (the bias alone is
// ~2 m, 1 sigma) and the per-fix innovation test cannot see a 4 m jump. But the innovation (fix minus
// filter) of consecutive fixes differs only by the white noise: a jump of either the GPS or the filter
// is a step in that sequence, many white sigmas tall. The detector follows the innovation's slow
// level and its fix-to-fix noise, both from the innovations themselves, and flags a fix that steps
// away from the level. It cannot say which of the two jumped; the map decides (relocalization).
#include <cstdint>
#include <optional>

#include <Eigen/Core>

namespace lidarloop {

struct GpsStepParams {
  // The level follows the innovations with this time constant: short against the bias's minutes, long
  // against the one second within which a jump must be told.
  double level_tau_s = 5.0;
  // Floor on the noise (m, per axis), so that a receiver that happens to repeat itself does not make
  // every next fix a step: the floor the localizer puts on any fix's sigma (GpsNoise::min_sigma_m).
  double min_noise_sigma_m = 0.5;
  // Chi^2, 2 degrees of freedom, at 99.99 %: a step is a fix this improbable under the noise.
  double step_gate = 18.42;
};

class GpsStepDetector {
 public:
  explicit GpsStepDetector(const GpsStepParams& params = {}) : p_(params) {}

  // The fix's innovation (fix minus filter, local frame, m) at t_ns. True if it steps away from the
  // level (it is then not learnt from: the level and noise stay those from before the step).
  bool step(int64_t t_ns, const Eigen::Vector2d& innovation);
  // Forget the level (after the filter itself moved by a relocalization, or to take a jumped GPS's
  // new level as its own): the next fix starts it anew.
  void restart() { level_.reset(); }
  // The filter moved by -delta (a relocalization while the GPS was steady): every innovation moves by
  // delta, and so does the level.
  void shift(const Eigen::Vector2d& delta);
  // The level before any current run of steps (nullopt before the first fix).
  const std::optional<Eigen::Vector2d>& level() const { return level_; }
  double noise_sigma_m() const;

 private:
  GpsStepParams p_;
  std::optional<Eigen::Vector2d> level_;
  std::optional<Eigen::Vector2d> last_;  // the last innovation learnt from
  double noise_variance_ = 0;            // per axis, of the fix-to-fix change of the innovation
  int noise_samples_ = 0;
  int64_t last_ns_ = 0;
};

}  // namespace lidarloop
