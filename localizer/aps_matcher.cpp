// APS intensity matching (sections 2.2.2 and 3.2, Eq. 8 and 14-18). See aps_matcher.hpp.
//
// Speed: the search offsets are whole cells of the vehicle frame, and so are the cells of S, so the
// map cell under S cell (c, r) at offset (i, j) is the map cell under vehicle cell (c + i, r + j).
// The map is therefore resampled once into a vehicle-frame window (S enlarged by the search range,
// one map lookup per window cell), and the search itself is index arithmetic on plain arrays.
#include "localizer/aps_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace lidarloop {
namespace {

// Two lengths that must agree (cell size vs map resolution, step vs whole cells) are compared with a
// relative tolerance: they come from YAML or arithmetic, not from the same literal.
constexpr double kLengthTolerance = 1e-6;

Eigen::Matrix2d rotation(double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

void check_grid_params(const IntensityGridParams& p, const char* who) {
  if (p.width_cells <= 0 || p.height_cells <= 0)
    throw std::invalid_argument(std::string(who) + ": grid width and height must be positive");
  if (!(std::isfinite(p.cell_m) && p.cell_m > 0))
    throw std::invalid_argument(std::string(who) + ": cell_m must be a positive number");
}

bool same_length(double a, double b) { return std::fabs(a - b) <= kLengthTolerance * std::max(std::fabs(a), std::fabs(b)); }

// Number of whole steps in [0, range] (a range that is a multiple of the step keeps its last step).
int steps_in(double range_m, double step_m) {
  return static_cast<int>(std::floor(range_m / step_m + kLengthTolerance));
}

}  // namespace

const IntensityCell& IntensityGrid::at(int col, int row) const {
  if (col < 0 || row < 0 || col >= params.width_cells || row >= params.height_cells)
    throw std::out_of_range("IntensityGrid::at: cell (" + std::to_string(col) + ", " + std::to_string(row) +
                            ") is outside the grid");
  return cells[size_t(row) * size_t(params.width_cells) + size_t(col)];
}

Eigen::Vector2d IntensityGrid::cell_centre(int col, int row) const {
  // The vehicle sits at the grid's centre: half the columns ahead of it, half behind.
  return {(col + 0.5 - 0.5 * params.width_cells) * params.cell_m, (row + 0.5 - 0.5 * params.height_cells) * params.cell_m};
}

IntensityGrid build_intensity_grid(const std::vector<Eigen::Vector3d>& ground_points_vehicle,
                                   const std::vector<double>& intensities, const Pose2d& pose,
                                   const IntensityGridParams& params) {
  check_grid_params(params, "build_intensity_grid");
  if (ground_points_vehicle.size() != intensities.size())
    throw std::invalid_argument("build_intensity_grid: " + std::to_string(ground_points_vehicle.size()) +
                                " points but " + std::to_string(intensities.size()) + " intensities");
  IntensityGrid grid;
  grid.pose = pose;
  grid.params = params;
  grid.cells.assign(size_t(params.width_cells) * size_t(params.height_cells), IntensityCell{});
  const double half_w = 0.5 * params.width_cells, half_h = 0.5 * params.height_cells;
  for (size_t i = 0; i < ground_points_vehicle.size(); ++i) {
    const Eigen::Vector3d& p = ground_points_vehicle[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(intensities[i])) continue;
    const double col = std::floor(p.x() / params.cell_m + half_w);
    const double row = std::floor(p.y() / params.cell_m + half_h);
    if (col < 0 || row < 0 || col >= params.width_cells || row >= params.height_cells) continue;
    grid.cells[size_t(row) * size_t(params.width_cells) + size_t(col)].add(intensities[i]);  // Eq. 8
  }
  return grid;
}

ApsResult aps_match(const IntensityGrid& S, IntensityMap& map, const ApsParams& params) {
  check_grid_params(S.params, "aps_match");
  const double cell = S.params.cell_m;
  if (!same_length(cell, map.header().resolution_m))
    throw std::invalid_argument("aps_match: grid cell size " + std::to_string(cell) + " m is not the map's resolution " +
                                std::to_string(map.header().resolution_m) + " m");
  if (S.cells.size() != size_t(S.params.width_cells) * size_t(S.params.height_cells))
    throw std::invalid_argument("aps_match: grid has " + std::to_string(S.cells.size()) + " cells, expected w_s * h_s");
  if (!(std::isfinite(params.step_m) && params.step_m > 0))
    throw std::invalid_argument("aps_match: step_m must be a positive number");
  const int step_cells = static_cast<int>(std::lround(params.step_m / cell));
  if (step_cells < 1 || !same_length(step_cells * cell, params.step_m))
    throw std::invalid_argument("aps_match: step_m must be a whole number of cells");
  if (!(params.lateral_range_m >= 0 && params.longitudinal_range_m >= 0 && std::isfinite(params.lateral_range_m) &&
        std::isfinite(params.longitudinal_range_m)))
    throw std::invalid_argument("aps_match: search ranges must be finite and non-negative");
  if (!(params.alpha > 0 && std::isfinite(params.alpha)))
    throw std::invalid_argument("aps_match: alpha must be a positive number");
  if (!(params.min_sigma > 0 && std::isfinite(params.min_sigma)))
    throw std::invalid_argument("aps_match: min_sigma must be a positive number");

  const int nx = steps_in(params.longitudinal_range_m, params.step_m);  // offsets -nx..nx along x
  const int ny = steps_in(params.lateral_range_m, params.step_m);
  const int margin_x = nx * step_cells, margin_y = ny * step_cells;  // window margin, in cells
  const int w = S.params.width_cells, h = S.params.height_cells;
  const int ww = w + 2 * margin_x, wh = h + 2 * margin_y;
  const Eigen::Matrix2d R = rotation(S.pose.yaw);
  const Eigen::Vector2d origin(S.pose.x, S.pose.y);

  // Usable cells of S (S_n > n_e), and a summed-area table of them: a window cell matters only if some
  // usable S cell looks at it at some offset, and on a road most of S is empty (the corridor's ground
  // only), so most of the window need not be read from the map at all.
  const uint32_t min_count = uint32_t(std::max(params.min_count, 0));
  auto usable = [&](int c, int r) { return S.cells[size_t(r) * size_t(w) + size_t(c)].count > min_count; };
  std::vector<int> usable_sat(size_t(w + 1) * size_t(h + 1), 0);
  for (int r = 0; r < h; ++r) {
    int row_usable = 0;
    for (int c = 0; c < w; ++c) {
      row_usable += usable(c, r) ? 1 : 0;
      usable_sat[size_t(r + 1) * size_t(w + 1) + size_t(c + 1)] =
          usable_sat[size_t(r) * size_t(w + 1) + size_t(c + 1)] + row_usable;
    }
  }
  // S cell (c, r) looks at window cells [c, c + 2 margin_x] x [r, r + 2 margin_y], so window cell
  // (wc, wr) is needed if S has a usable cell in [wc - 2 margin_x, wc] x [wr - 2 margin_y, wr].
  auto needed = [&](int wc, int wr) {
    const int c0 = std::max(wc - 2 * margin_x, 0), c1 = std::min(wc, w - 1);
    const int r0 = std::max(wr - 2 * margin_y, 0), r1 = std::min(wr, h - 1);
    if (c0 > c1 || r0 > r1) return false;
    auto at = [&](int c, int r) { return usable_sat[size_t(r) * size_t(w + 1) + size_t(c)]; };
    return at(c1 + 1, r1 + 1) - at(c0, r1 + 1) - at(c1 + 1, r0) + at(c0, r0) > 0;
  };

  // The map under the vehicle-frame window: mean, floored standard deviation, and a summed-area table
  // of the cells without data (to ask in O(1) whether an S cell stays on the map at every offset; a cell
  // nobody needs counts as present, which no question can tell apart).
  // Single precision for the search: intensities are whole counts 0-255 and the sums a few thousand
  // z-scores, far inside float's 7 digits, and the inner loop does twice the offsets per instruction.
  std::vector<float> map_mean(size_t(ww) * size_t(wh), 0.0f), map_sigma(size_t(ww) * size_t(wh), float(params.min_sigma));
  std::vector<int> missing_sat(size_t(ww + 1) * size_t(wh + 1), 0);
  for (int r = 0; r < wh; ++r) {
    int row_missing = 0;
    for (int c = 0; c < ww; ++c) {
      if (needed(c, r)) {
        const Eigen::Vector2d local = origin + R * S.cell_centre(c - margin_x, r - margin_y);
        const std::optional<IntensityCell> m = map.cell(local);
        const size_t k = size_t(r) * size_t(ww) + size_t(c);
        if (m && m->count > 0) {
          map_mean[k] = float(m->mean);
          // Eq. 14 as printed adds variances and squares the sum, which is dimensionally intensity^4
          // over intensity^2; reading sigma as the standard deviation makes the exponent a squared
          // z-score, as in APS.
          map_sigma[k] = float(std::max(std::sqrt(m->variance()), params.min_sigma));
        } else {
          ++row_missing;
        }
      }
      missing_sat[size_t(r + 1) * size_t(ww + 1) + size_t(c + 1)] =
          missing_sat[size_t(r) * size_t(ww + 1) + size_t(c + 1)] + row_missing;
    }
  }
  // Missing map cells in window rows [r0, r0 + rows), columns [c0, c0 + cols).
  auto missing_in = [&](int c0, int r0, int cols, int rows) {
    auto at = [&](int c, int r) { return missing_sat[size_t(r) * size_t(ww + 1) + size_t(c)]; };
    return at(c0 + cols, r0 + rows) - at(c0, r0 + rows) - at(c0 + cols, r0) + at(c0, r0);
  };

  // Eq. 14 in logs: log P(o) = alpha * sum -(m_r - s_r)^2 / (2 (m_sigma + s_sigma)^2). The loop over
  // offsets is innermost: each offset has its own accumulator, so it vectorises.
  const int ox = 2 * nx + 1, oy = 2 * ny + 1;
  std::vector<float> sum_sq(size_t(ox) * size_t(oy), 0.0f);  // sum of squared z-scores per offset
  int used = 0;
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      if (!usable(c, r)) continue;  // effective area: S_n > n_e
      const IntensityCell& s = S.cells[size_t(r) * size_t(w) + size_t(c)];
      // Window cell (c, r) is S cell (c, r) shifted by the most negative offset.
      if (missing_in(c, r, 2 * margin_x + 1, 2 * margin_y + 1) != 0) continue;
      ++used;
      const float s_r = float(s.mean), s_sigma = float(std::max(std::sqrt(s.variance()), params.min_sigma));
      for (int j = 0; j < oy; ++j) {
        const size_t base = size_t(r + j * step_cells) * size_t(ww) + size_t(c);
        float* acc = &sum_sq[size_t(j) * size_t(ox)];
        for (int i = 0; i < ox; ++i) {
          const size_t k = base + size_t(i * step_cells);
          const float d = map_mean[k] - s_r, e = map_sigma[k] + s_sigma;
          acc[i] += d * d / (e * e);
        }
      }
    }
  }

  ApsResult result;
  result.cells_used = used;
  result.position = origin;
  const Eigen::Vector2d range(nx * params.step_m, ny * params.step_m);
  if (used < params.min_cells) {
    // No information beyond "somewhere in the window": a uniform spread over it (variance range^2/3).
    const Eigen::Matrix2d c = (range.array().square() / 3.0).matrix().asDiagonal();
    result.covariance = R * c * R.transpose();
    return result;
  }

  // Normalise by the best offset before exponentiating: the raw sums are thousands, exp() would be 0.
  std::vector<double> log_p(sum_sq.size());
  for (size_t k = 0; k < sum_sq.size(); ++k) log_p[k] = -0.5 * params.alpha * double(sum_sq[k]);
  const auto best_at = std::max_element(log_p.begin(), log_p.end());
  const double best = *best_at;
  const int best_i = int((best_at - log_p.begin()) % ox), best_j = int((best_at - log_p.begin()) / ox);
  result.peak_on_edge = (nx > 0 && (best_i == 0 || best_i == ox - 1)) || (ny > 0 && (best_j == 0 || best_j == oy - 1));
  double total = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  for (int j = 0; j < oy; ++j) {
    for (int i = 0; i < ox; ++i) {
      const double p = std::exp(log_p[size_t(j) * size_t(ox) + size_t(i)] - best);
      const Eigen::Vector2d o((i - nx) * params.step_m, (j - ny) * params.step_m);
      total += p;
      mean += p * o;
      second += p * o * o.transpose();
    }
  }
  mean /= total;  // Eq. 15-16: centre of mass
  Eigen::Matrix2d cov = second / total - mean * mean.transpose();
  // A distribution on a grid of steps can put all its mass on one offset; the estimate is still only
  // known to within a step, so add the variance of a uniform spread over one step (step^2 / 12).
  const double quantisation = params.step_m * params.step_m / 12.0;
  cov.diagonal().array() += quantisation;

  result.ok = true;
  result.offset_vehicle = mean;
  result.position = origin + R * mean;  // Eq. 17-18, the offset rotated from the vehicle frame
  result.covariance = R * cov * R.transpose();
  return result;
}

}  // namespace lidarloop
