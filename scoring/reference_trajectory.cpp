#include "scoring/reference_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/pose2d.hpp"
#include "common/units.hpp"
#include "sim/counter_rng.hpp"

namespace lidarloop {
namespace {

// The reference's own random stream of the scenario seed (sim/counter_rng.hpp): independent of every
// draw of the simulation, which never reads it.
constexpr uint64_t kReferenceStream = 0x7265666572656e63;  // "referenc"
// Draws per sample, in this order: x, y, yaw.
constexpr uint64_t kAxes = 3, kXDraw = 0, kYDraw = 1, kYawDraw = 2;

struct Axis {
  double sigma = 0;
  uint64_t draw = 0;
};

}  // namespace

std::vector<ReferenceError> reference_errors(const std::vector<int64_t>& stamps_ns, const ReferenceConfig& config,
                                             uint64_t scenario_seed) {
  if (!std::is_sorted(stamps_ns.begin(), stamps_ns.end()))
    throw std::invalid_argument("reference_errors: the stamps are not sorted");
  if (!(config.sigma_xy_m >= 0) || !(config.heading_sigma_rad >= 0))
    throw std::invalid_argument("reference_errors: a sigma is negative");
  if (!(config.correlation_s > 0))
    throw std::invalid_argument("reference_errors: the correlation time is not positive");
  const CounterRng rng(scenario_seed, kReferenceStream);
  const Axis axes[kAxes] = {
      {config.sigma_xy_m, kXDraw}, {config.sigma_xy_m, kYDraw}, {config.heading_sigma_rad, kYawDraw}};
  std::vector<ReferenceError> out;
  out.reserve(stamps_ns.size());
  double e[kAxes] = {0, 0, 0};
  for (size_t k = 0; k < stamps_ns.size(); ++k) {
    // The first sample from the stationary distribution: phi = 0 draws it whole.
    const double phi = k == 0 ? 0.0 : std::exp(-ns_to_s(stamps_ns[k] - stamps_ns[k - 1]) / config.correlation_s);
    const double innovation = std::sqrt(1.0 - phi * phi);
    for (const Axis& a : axes) e[a.draw] = phi * e[a.draw] + a.sigma * innovation * rng.normal(kAxes * k + a.draw);
    out.push_back({e[kXDraw], e[kYDraw], e[kYawDraw]});
  }
  return out;
}

std::vector<TruthPose> reference_trajectory(const std::vector<TruthPose>& truth, const ReferenceConfig& config,
                                            uint64_t scenario_seed) {
  if (config.kind == ReferenceConfig::Kind::none) return truth;
  std::vector<int64_t> stamps;
  stamps.reserve(truth.size());
  for (const TruthPose& t : truth) stamps.push_back(t.stamp_ns);
  const std::vector<ReferenceError> errors = reference_errors(stamps, config, scenario_seed);
  std::vector<TruthPose> out = truth;
  for (size_t k = 0; k < out.size(); ++k) {
    out[k].pose.x += errors[k].x_m;
    out[k].pose.y += errors[k].y_m;
    out[k].pose.yaw = wrap_angle(out[k].pose.yaw + errors[k].yaw_rad);
  }
  return out;
}

}  // namespace lidarloop
