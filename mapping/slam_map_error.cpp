#include "mapping/slam_map_error.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mapping/survey_error.hpp"

namespace lidarloop {

std::string SlamMapErrorConfig::describe() const {
  return "slam_absolute_m=" + exact_number(absolute_sigma_m) + " slam_relative_m=" + exact_number(relative_sigma_m) +
         " slam_relative_over_m=" + exact_number(relative_over_m) + " slam_waves=" + std::to_string(waves);
}

double slam_correlation_length(const SlamMapErrorConfig& c) {
  if (!(c.absolute_sigma_m > 0 && c.relative_sigma_m > 0 && c.relative_over_m > 0 && c.waves > 0))
    throw std::invalid_argument("slam map error: the sigmas, the distance and the wave count must be positive");
  // 1 - exp(-d^2 / (2 l^2)) = relative^2 / (2 absolute^2), which must lie in (0, 1).
  const double fraction = c.relative_sigma_m * c.relative_sigma_m / (2 * c.absolute_sigma_m * c.absolute_sigma_m);
  if (!(fraction < 1))
    throw std::invalid_argument("slam map error: the relative error must stay below sqrt(2) times the absolute");
  return c.relative_over_m / std::sqrt(-2 * std::log1p(-fraction));
}

SlamErrorField::SlamErrorField(const SlamMapErrorConfig& c, std::mt19937_64& rng) {
  const double length = slam_correlation_length(c);
  // sigma per axis = absolute / sqrt(2); a cosine of amplitude a has mean square a^2 / 2 over space.
  amplitude_ = c.absolute_sigma_m / std::sqrt(2.0) * std::sqrt(2.0 / c.waves);
  std::normal_distribution<double> wavenumber(0.0, 1.0 / length);
  std::uniform_real_distribution<double> phase(0.0, 2 * std::numbers::pi);
  for (auto* axis : {&east_, &north_})
    for (int m = 0; m < c.waves; ++m) {
      const double kx = wavenumber(rng), ky = wavenumber(rng);
      axis->push_back({{kx, ky}, phase(rng)});
    }
}

Pose2d SlamErrorField::at(const Eigen::Vector2d& p) const {
  // e = a sum cos(k.p + phase); de/dp = -a sum k sin(k.p + phase).
  double east = 0, north = 0, d_east_d_north = 0, d_north_d_east = 0;
  for (const Wave& w : east_) {
    const double arg = w.k.dot(p) + w.phase;
    east += std::cos(arg);
    d_east_d_north -= w.k.y() * std::sin(arg);
  }
  for (const Wave& w : north_) {
    const double arg = w.k.dot(p) + w.phase;
    north += std::cos(arg);
    d_north_d_east -= w.k.x() * std::sin(arg);
  }
  return {amplitude_ * east, amplitude_ * north, amplitude_ * 0.5 * (d_north_d_east - d_east_d_north)};
}

}  // namespace lidarloop
