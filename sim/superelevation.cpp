#include "sim/superelevation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace lidarloop {

namespace {

// V^2 / (127 R) is V (km/h) squared over g R in consistent units: 3.6^2 * 9.81 = 127.
constexpr double kSpeedFactor = 127.0;

// Linear interpolation in a table of (speed km/h, value), clamped at its ends.
double interpolate(const std::array<std::array<double, 2>, 6>& table, double speed) {
  if (speed <= table.front()[0]) return table.front()[1];
  for (size_t k = 1; k < table.size(); ++k)
    if (speed <= table[k][0]) {
      const double t = (speed - table[k - 1][0]) / (table[k][0] - table[k - 1][0]);
      return table[k - 1][1] + t * (table[k][1] - table[k - 1][1]);
    }
  return table.back()[1];
}

// Heading change per metre at sample k, from the samples a few places either side.
double curvature(const Polyline2d& line, const std::vector<double>& s, size_t k) {
  constexpr size_t kReach = 4;
  const size_t a = k >= kReach ? k - kReach : 0, b = std::min(s.size() - 1, k + kReach);
  if (s[b] <= s[a]) return 0;
  auto heading = [&](size_t i) {
    const Eigen::Vector2d t = sample_polyline(line, s[i]).tangent;
    return std::atan2(t.y(), t.x());
  };
  return std::remainder(heading(b) - heading(a), 2 * std::numbers::pi) / (s[b] - s[a]);
}

}  // namespace

double low_speed_side_friction(double speed_kmh) {
  static constexpr std::array<std::array<double, 2>, 6> kTable = {
      {{20, 0.35}, {30, 0.28}, {40, 0.23}, {50, 0.19}, {60, 0.17}, {70, 0.15}}};
  return interpolate(kTable, speed_kmh);
}

double max_relative_gradient(double speed_kmh) {
  static constexpr std::array<std::array<double, 2>, 6> kTable = {
      {{20, 0.0080}, {30, 0.0075}, {40, 0.0070}, {50, 0.0065}, {60, 0.0060}, {70, 0.0055}}};
  return interpolate(kTable, speed_kmh);
}

double superelevation_rate(double radius, double speed_kmh, double cross_slope, double max_rate) {
  if (!(radius > 0) || max_rate <= 0) return 0;
  const double needed = speed_kmh * speed_kmh / (kSpeedFactor * radius) - low_speed_side_friction(speed_kmh);
  if (needed <= 0) return 0;
  return std::min(max_rate, std::max(needed, cross_slope));
}

std::vector<double> superelevation_profile(const Polyline2d& centreline, bool closed, const std::vector<double>& s,
                                           double speed_kmh, double cross_slope, double max_rate, double half_width) {
  const size_t n = s.size();
  std::vector<double> full(n, 0.0), e(n, 0.0);  // the bank each place's own curvature needs; the bank
  for (size_t k = 0; k < n; ++k) {
    const double kappa = curvature(centreline, s, k);
    if (kappa == 0) continue;
    full[k] = std::copysign(superelevation_rate(1 / std::abs(kappa), speed_kmh, cross_slope, max_rate), kappa);
  }
  // Runoff: the outside edge's slope turns from the crown's fall to the bank's rise at most this much
  // per metre along the road, so its grade relative to the centreline stays within AASHTO's maximum.
  // It turns twice as fast as the bank while the crown is removed (banked_section), so the ramp is in
  // the edge's slope q, from -cross_slope on a tangent.
  const double rate = max_relative_gradient(speed_kmh) / half_width;
  const double length = s.empty() ? 0 : s.back();
  std::vector<double> q(n, -cross_slope);
  std::vector<int> side(n, 0);
  for (size_t k = 0; k < n; ++k) {
    if (full[k] == 0) continue;
    for (size_t j = 0; j < n; ++j) {
      double gap = std::abs(s[j] - s[k]);
      if (closed) gap = std::min(gap, length - gap);
      const double reach = std::abs(full[k]) - rate * gap;
      if (reach > q[j]) q[j] = reach, side[j] = full[k] > 0 ? 1 : -1;
    }
  }
  for (size_t k = 0; k < n; ++k) {
    const double bank = q[k] <= cross_slope ? (q[k] + cross_slope) / 2 : q[k];
    e[k] = side[k] * std::max(0.0, bank);
  }
  return e;
}

double banked_section(double lateral, double cross_slope, double e) {
  const double distance = std::abs(lateral), bank = std::abs(e);
  const bool inside = e != 0 && (lateral > 0) == (e > 0);
  if (inside) return -std::max(cross_slope, bank) * distance;
  // The outside half: crown removed (level at half the crown's slope in bank), then rising with the bank.
  const double rise = bank <= cross_slope ? 2 * bank - cross_slope : bank;
  return rise * distance;
}

}  // namespace lidarloop
