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

#include "localizer/cell_counts.hpp"

namespace lidarloop {
namespace {

// Two lengths that must agree (cell size vs map resolution, step vs whole cells) are compared with a
// relative tolerance: they come from YAML or arithmetic, not from the same literal.
constexpr double kLengthTolerance = 1e-6;
// z_score_sums scores offsets in rows of whole vectors of this many floats (AVX2's eight), so that no
// row ends in a part vector done a float at a time; the offsets past a row's end are scored and dropped.
constexpr int kOffsetLanes = 8;

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

bool same_length(double a, double b) {
  return std::fabs(a - b) <= kLengthTolerance * std::max(std::fabs(a), std::fabs(b));
}

// Number of whole steps in [0, range] (a range that is a multiple of the step keeps its last step).
int steps_in(double range_m, double step_m) {
  return static_cast<int>(std::floor(range_m / step_m + kLengthTolerance));
}

// S against the map it is matched on, and the parameters of Eq. 14 (the window's are checked by
// aps_search_window).
void check_aps_inputs(const IntensityGrid& S, double map_resolution_m, const ApsParams& params) {
  check_grid_params(S.params, "aps_match");
  if (!same_length(S.params.cell_m, map_resolution_m))
    throw std::invalid_argument("aps_match: grid cell size " + std::to_string(S.params.cell_m) +
                                " m is not the map's resolution " + std::to_string(map_resolution_m) + " m");
  if (S.cells.size() != size_t(S.params.width_cells) * size_t(S.params.height_cells))
    throw std::invalid_argument("aps_match: grid has " + std::to_string(S.cells.size()) + " cells, expected w_s * h_s");
  if (!(params.alpha > 0 && std::isfinite(params.alpha)))
    throw std::invalid_argument("aps_match: alpha must be a positive number");
  if (!(params.min_sigma > 0 && std::isfinite(params.min_sigma)))
    throw std::invalid_argument("aps_match: min_sigma must be a positive number");
}

// The effective area of S: cells with S_n > n_e (fewer points: the mean is too noisy).
bool usable(const IntensityCell& s, const ApsParams& params) {
  return s.count > uint32_t(std::max(params.min_count, 0));
}

// Eq. 14 as printed adds variances and squares the sum, which is dimensionally intensity^4 over
// intensity^2; reading sigma as the standard deviation makes the exponent a squared z-score, as in APS.
double floored_sigma(const IntensityCell& cell, double min_sigma) {
  return std::max(std::sqrt(cell.variance()), min_sigma);
}

// Where S is usable. On a road most of S is empty (the corridor's ground only), so most of the map
// window is never looked at and need not be read.
CellCounts usable_cells(const IntensityGrid& S, const ApsParams& params) {
  const int w = S.params.width_cells;
  return CellCounts(w, S.params.height_cells,
                    [&](int c, int r) { return usable(S.cells[size_t(r) * size_t(w) + size_t(c)], params); });
}

// S cell (c, r) looks at window cells [c, c + 2 margin_x] x [r, r + 2 margin_y], so window cell
// (wc, wr) is needed if S has a usable cell in [wc - 2 margin_x, wc] x [wr - 2 margin_y, wr].
bool needed(const CellCounts& usable, const ApsSearchWindow& window, int wc, int wr) {
  const int c0 = std::max(wc - 2 * window.margin_x(), 0), c1 = std::min(wc, usable.cols() - 1);
  const int r0 = std::max(wr - 2 * window.margin_y(), 0), r1 = std::min(wr, usable.rows() - 1);
  if (c0 > c1 || r0 > r1) return false;
  return usable.in(c0, r0, c1 - c0 + 1, r1 - r0 + 1) > 0;
}

// The map under S enlarged by the search margins, in S's vehicle-frame cells: window cell (c, r) is
// S cell (c - margin_x, r - margin_y) at offset zero. Single precision for the search: intensities are
// whole counts 0-255 and the sums a few thousand z-scores, far inside float's 7 digits, and the inner
// loop does twice the offsets per instruction.
struct MapWindow {
  int cols = 0, rows = 0;
  std::vector<float> mean;   // NaN where the map has no data
  std::vector<float> sigma;  // floored standard deviation
  // Window cells without map data, to ask in O(1) whether an S cell stays on the map at every offset.
  // A cell nobody needs counts as present, which no question can tell apart.
  CellCounts missing;

  size_t index(int c, int r) const { return size_t(r) * size_t(cols) + size_t(c); }
};

// Reads the map only where usable S cells can look (one lookup per needed window cell). The arrays run
// on past the window for z_score_sums' rows of whole vectors: their last row reads up to
// kOffsetLanes - 1 offsets beyond the window.
MapWindow map_under_window(const IntensityGrid& S, IntensityMap& map, const ApsSearchWindow& window,
                           const CellCounts& usable, double min_sigma) {
  const int cols = S.params.width_cells + 2 * window.margin_x(), rows = S.params.height_cells + 2 * window.margin_y();
  const auto at = [cols](int c, int r) { return size_t(r) * size_t(cols) + size_t(c); };
  const Eigen::Matrix2d R = rotation(S.pose.yaw);
  const Eigen::Vector2d origin(S.pose.x, S.pose.y);
  const size_t size = size_t(cols) * size_t(rows) + size_t(kOffsetLanes - 1) * size_t(window.step_cells);
  std::vector<float> mean(size, 0.0f), sigma(size, float(min_sigma));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!needed(usable, window, c, r)) continue;
      const Eigen::Vector2d local = origin + R * S.cell_centre(c - window.margin_x(), r - window.margin_y());
      const std::optional<IntensityCell> m = map.cell(local);
      if (m && m->count > 0) {
        mean[at(c, r)] = float(m->mean);
        sigma[at(c, r)] = float(floored_sigma(*m, min_sigma));
      } else {
        mean[at(c, r)] = std::numeric_limits<float>::quiet_NaN();
      }
    }
  }
  CellCounts missing(cols, rows, [&](int c, int r) { return std::isnan(mean[at(c, r)]); });
  return {cols, rows, std::move(mean), std::move(sigma), std::move(missing)};
}

// Eq. 14's exponent per offset, without its -alpha/2: the sum of squared z-scores
// (m_r - s_r)^2 / (m_sigma + s_sigma)^2 over the cells of S that take part.
struct ZScoreSums {
  std::vector<float> per_offset;  // row-major, offsets_x() per row
  int cells_used = 0;
};

// One row of offsets of Eq. 14's exponent for one cell of S: acc[i] += z-score^2 of the map cell
// i * stride along. Inlined into both calls below, so the usual stride of one cell becomes plain
// vector loads (a stride the compiler does not know is loaded a float at a time).
[[gnu::always_inline]] inline void add_z_scores(float* acc, const float* map_mean, const float* map_sigma, int n,
                                                int stride, float s_r, float s_sigma) {
  for (int i = 0; i < n; ++i) {
    const float d = map_mean[i * stride] - s_r, e = map_sigma[i * stride] + s_sigma;
    acc[i] += d * d / (e * e);
  }
}

// A cell of S takes part if it is usable and the map has data under it at every offset, so every
// offset is scored on the same cells. The loop over offsets is innermost: each offset has its own
// accumulator, so it vectorises. Its divisions bound it, so it is also built for AVX2 (eight floats a
// division instead of four), chosen at load time where the processor has it. The same bits either way:
// each lane is IEEE single precision, and AVX2 alone brings no fused multiply-add to contract into.
[[gnu::target_clones("avx2", "default")]] ZScoreSums z_score_sums(const IntensityGrid& S, const MapWindow& m,
                                                                  const ApsSearchWindow& window,
                                                                  const ApsParams& params) {
  const int w = S.params.width_cells, h = S.params.height_cells;
  const int ox = window.offsets_x(), oy = window.offsets_y(), step = window.step_cells;
  const float* map_mean = m.mean.data();
  const float* map_sigma = m.sigma.data();
  // Each row of offsets rounded up to whole vectors: the offsets past ox read the map window further
  // along (map_under_window leaves room at its end), and are dropped below.
  const int row = (ox + kOffsetLanes - 1) / kOffsetLanes * kOffsetLanes;
  std::vector<float> padded(size_t(row) * size_t(oy), 0.0f);
  ZScoreSums sums;
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const IntensityCell& s = S.cells[size_t(r) * size_t(w) + size_t(c)];
      if (!usable(s, params)) continue;
      // Window cell (c, r) is S cell (c, r) shifted by the most negative offset.
      if (m.missing.in(c, r, 2 * window.margin_x() + 1, 2 * window.margin_y() + 1) != 0) continue;
      ++sums.cells_used;
      const float s_r = float(s.mean), s_sigma = float(floored_sigma(s, params.min_sigma));
      for (int j = 0; j < oy; ++j) {
        const size_t base = m.index(c, r + j * step);
        float* acc = &padded[size_t(j) * size_t(row)];
        if (step == 1)
          add_z_scores(acc, map_mean + base, map_sigma + base, row, 1, s_r, s_sigma);
        else
          add_z_scores(acc, map_mean + base, map_sigma + base, row, step, s_r, s_sigma);
      }
    }
  }
  sums.per_offset.resize(size_t(ox) * size_t(oy));
  for (int j = 0; j < oy; ++j) std::copy_n(padded.begin() + long(j) * row, ox, sums.per_offset.begin() + long(j) * ox);
  return sums;
}

// ApsResult::yaw_coupling in the vehicle frame, at offset (i, j) of the window: the translation t that
// best undoes a turn e of S minimises sum w (g . (t + e perp(c)))^2 over the cells taking part, with g
// the map's intensity gradient under cell c (central differences), w = 1 / (m_sigma + s_sigma)^2 and
// perp(c) = (-c_y, c_x); t = -e A^-1 b. A direction the gradients leave free gets no coupling (A is
// regularised by a millionth of its trace).
Eigen::Vector2d yaw_coupling(const IntensityGrid& S, const MapWindow& m, const ApsSearchWindow& window,
                             const ApsParams& params, int i, int j) {
  const int w = S.params.width_cells, h = S.params.height_cells;
  const double cell = S.params.cell_m;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const IntensityCell& s = S.cells[size_t(r) * size_t(w) + size_t(c)];
      if (!usable(s, params)) continue;
      if (m.missing.in(c, r, 2 * window.margin_x() + 1, 2 * window.margin_y() + 1) != 0) continue;
      const int wc = c + i * window.step_cells, wr = r + j * window.step_cells;
      if (wc < 1 || wr < 1 || wc + 1 >= m.cols || wr + 1 >= m.rows) continue;
      const float left = m.mean[m.index(wc - 1, wr)], right = m.mean[m.index(wc + 1, wr)];
      const float down = m.mean[m.index(wc, wr - 1)], up = m.mean[m.index(wc, wr + 1)];
      if (std::isnan(left) || std::isnan(right) || std::isnan(down) || std::isnan(up)) continue;
      const Eigen::Vector2d g((right - left) / (2 * cell), (up - down) / (2 * cell));
      const double e = m.sigma[m.index(wc, wr)] + floored_sigma(s, params.min_sigma);
      const Eigen::Matrix2d G = g * g.transpose() / (e * e);
      const Eigen::Vector2d centre = S.cell_centre(c, r) + window.offset(i, j);
      A += G;
      b += G * Eigen::Vector2d(-centre.y(), centre.x());
    }
  }
  const double trace = A.trace();
  if (!(trace > 0)) return Eigen::Vector2d::Zero();
  return -(A + 1e-6 * trace * Eigen::Matrix2d::Identity()).ldlt().solve(b);
}

// No information beyond "somewhere in the window": a uniform spread over it (variance range^2 / 3),
// vehicle frame.
Eigen::Matrix2d uniform_over_window(const ApsSearchWindow& window) {
  const Eigen::Vector2d range(window.nx * window.step_m, window.ny * window.step_m);
  return (range.array().square() / 3.0).matrix().asDiagonal();
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
  return {(col + 0.5 - 0.5 * params.width_cells) * params.cell_m,
          (row + 0.5 - 0.5 * params.height_cells) * params.cell_m};
}

IntensityGridBuilder::IntensityGridBuilder(const Pose2d& pose, const IntensityGridParams& params)
    : pose_(pose), params_(params) {
  check_grid_params(params, "IntensityGridBuilder");
  cells_.assign(size_t(params.width_cells) * size_t(params.height_cells), Sums{});
}

namespace {

// intensity_cell_index's constants, read once for a loop over many points.
struct CellIndexer {
  Eigen::Array2d half_extent;  // the grid's half size in cells: its columns and rows from 0 at its edge
  double cols, rows, cell_m;
  size_t width;

  explicit CellIndexer(const IntensityGridParams& p)
      : half_extent(0.5 * p.width_cells, 0.5 * p.height_cells),
        cols(p.width_cells),
        rows(p.height_cells),
        cell_m(p.cell_m),
        width(size_t(p.width_cells)) {}

  // x and y are divided as one pair: one vector division, each lane rounded as the scalar one is.
  std::optional<size_t> operator()(const Eigen::Vector2d& point_vehicle) const {
    const Eigen::Array2d q = point_vehicle.array() / cell_m + half_extent;
    // `!(a >= 0 && a < n)` also refuses a NaN.
    if (!(q.x() >= 0 && q.x() < cols && q.y() >= 0 && q.y() < rows)) return std::nullopt;
    return size_t(q.y()) * width + size_t(q.x());  // floor: both are >= 0
  }
};

}  // namespace

std::optional<size_t> intensity_cell_index(const IntensityGridParams& params, const Eigen::Vector2d& point_vehicle) {
  return CellIndexer(params)(point_vehicle);
}

std::vector<char> in_marked_cells(const IntensityGridParams& params, const std::vector<char>& marked,
                                  const std::vector<Eigen::Vector3d>& points, const std::vector<size_t>& indices) {
  const CellIndexer cell_index(params);
  std::vector<char> out(indices.size(), 0);
  for (size_t k = 0; k < indices.size(); ++k) {
    const std::optional<size_t> cell = cell_index(points[indices[k]].head<2>());
    out[k] = cell && marked[*cell];
  }
  return out;
}

std::vector<char> cells_near_obstacles(const std::vector<Eigen::Vector2d>& obstacles, const IntensityGridParams& p) {
  check_grid_params(p, "cells_near_obstacles");
  const int w = p.width_cells, h = p.height_cells;
  std::vector<char> near(size_t(w) * size_t(h), 0);
  if (!(p.obstacle_distance > 0)) return near;
  const double d2 = p.obstacle_distance * p.obstacle_distance;
  // A parked row returns thousands of points a scan, a few to a cell. So the points are grouped by the
  // cell they fall in (on S grown by the reach on every side: a car just off S still masks S's edge),
  // and each cell's neighbours are settled once: those within the distance of any point of the cell are
  // marked without a test, those beyond it of every point skipped, and only the ring between tests the
  // cell's points, until one is near enough.
  const int reach = int(std::ceil(p.obstacle_distance / p.cell_m)) + 1;
  const int pw = w + 2 * reach, ph = h + 2 * reach;
  auto padded_cell = [&](const Eigen::Vector2d& o) -> std::optional<size_t> {
    const double col = std::floor(o.x() / p.cell_m + 0.5 * w) + reach,
                 row = std::floor(o.y() / p.cell_m + 0.5 * h) + reach;
    if (!(col >= 0 && col < pw && row >= 0 && row < ph)) return std::nullopt;  // off S's reach, or NaN
    return size_t(row) * size_t(pw) + size_t(col);
  };
  std::vector<uint32_t> start(size_t(pw) * size_t(ph) + 1, 0);
  for (const Eigen::Vector2d& o : obstacles)
    if (const auto k = padded_cell(o)) ++start[*k + 1];
  for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<Eigen::Vector2d> sorted(start.back());
  for (const Eigen::Vector2d& o : obstacles)
    if (const auto k = padded_cell(o)) sorted[fill[*k]++] = o;

  // Neighbour offsets by how far their centre can be from a point of the cell: the centres' distance
  // give or take half the cell's diagonal (with a margin for rounding: the test itself decides then).
  struct Offset {
    int dc, dr;
  };
  std::vector<Offset> certain, tested;
  const double half_diagonal = p.cell_m * std::sqrt(0.5), margin = 1e-9 * p.obstacle_distance;
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc) {
      const double apart = std::hypot(dc, dr) * p.cell_m;
      if (apart + half_diagonal < p.obstacle_distance - margin)
        certain.push_back({dc, dr});
      else if (apart - half_diagonal <= p.obstacle_distance + margin)
        tested.push_back({dc, dr});
    }
  for (int pr = 0; pr < ph; ++pr)
    for (int pc = 0; pc < pw; ++pc) {
      const size_t k = size_t(pr) * size_t(pw) + size_t(pc);
      if (start[k] == start[k + 1]) continue;
      const int c = pc - reach, r = pr - reach;  // in S's cells
      for (const Offset& o : certain)
        if (c + o.dc >= 0 && c + o.dc < w && r + o.dr >= 0 && r + o.dr < h)
          near[size_t(r + o.dr) * size_t(w) + size_t(c + o.dc)] = 1;
      for (const Offset& o : tested) {
        const int tc = c + o.dc, tr = r + o.dr;
        if (tc < 0 || tc >= w || tr < 0 || tr >= h) continue;
        char& cell = near[size_t(tr) * size_t(w) + size_t(tc)];
        if (cell) continue;
        const double x = (tc + 0.5 - 0.5 * w) * p.cell_m, y = (tr + 0.5 - 0.5 * h) * p.cell_m;
        for (uint32_t i = start[k]; i < start[k + 1] && !cell; ++i) {
          const double cx = x - sorted[i].x(), cy = y - sorted[i].y();
          cell = cx * cx + cy * cy <= d2;
        }
      }
    }
  return near;
}

bool IntensityGridBuilder::add(const Eigen::Vector2d& point_vehicle, double intensity) {
  if (!std::isfinite(intensity)) return false;
  const std::optional<size_t> cell = intensity_cell_index(params_, point_vehicle);
  if (!cell) return false;
  Sums& c = cells_[*cell];
  ++c.count;
  c.sum += intensity;
  c.sum_sq += intensity * intensity;
  return true;
}

void IntensityGridBuilder::add(const std::vector<Eigen::Vector2d>& points_vehicle,
                               const std::vector<double>& intensities) {
  if (points_vehicle.size() != intensities.size())
    throw std::invalid_argument("IntensityGridBuilder::add: " + std::to_string(points_vehicle.size()) + " points but " +
                                std::to_string(intensities.size()) + " intensities");
  for (size_t i = 0; i < points_vehicle.size(); ++i) add(points_vehicle[i], intensities[i]);
}

long IntensityGridBuilder::cells_with_more_than(uint32_t points) const {
  return long(std::count_if(cells_.begin(), cells_.end(), [points](const Sums& c) { return c.count > points; }));
}

IntensityGrid IntensityGridBuilder::grid() const {
  IntensityGrid grid;
  grid.pose = pose_;
  grid.params = params_;
  grid.cells.resize(cells_.size());
  for (size_t k = 0; k < cells_.size(); ++k) {
    const Sums& c = cells_[k];
    if (c.count == 0) continue;
    // Eq. 8's mean and spread from the sums; intensities are counts up to a few hundred, so the sum of
    // squares stays exact to far below a count's square even for thousands of points.
    const double n = double(c.count), mean = c.sum / n;
    grid.cells[k] = {c.count, float(mean), float(std::max(0.0, c.sum_sq - c.sum * mean))};
  }
  return grid;
}

IntensityGrid build_intensity_grid(const std::vector<Eigen::Vector3d>& ground_points_vehicle,
                                   const std::vector<double>& intensities, const Pose2d& pose,
                                   const IntensityGridParams& params) {
  IntensityGridBuilder builder(pose, params);
  if (ground_points_vehicle.size() != intensities.size())
    throw std::invalid_argument("build_intensity_grid: " + std::to_string(ground_points_vehicle.size()) +
                                " points but " + std::to_string(intensities.size()) + " intensities");
  for (size_t i = 0; i < ground_points_vehicle.size(); ++i)
    builder.add(ground_points_vehicle[i].head<2>(), intensities[i]);
  return builder.grid();
}

ApsSearchWindow aps_search_window(const ApsParams& params, double cell_m) {
  if (!(std::isfinite(cell_m) && cell_m > 0))
    throw std::invalid_argument("aps_search_window: cell_m must be a positive number");
  if (!(std::isfinite(params.step_m) && params.step_m > 0))
    throw std::invalid_argument("aps_search_window: step_m must be a positive number");
  const int step_cells = static_cast<int>(std::lround(params.step_m / cell_m));
  if (step_cells < 1 || !same_length(step_cells * cell_m, params.step_m))
    throw std::invalid_argument("aps_search_window: step_m must be a whole number of cells");
  if (!(params.lateral_range_m >= 0 && params.longitudinal_range_m >= 0 && std::isfinite(params.lateral_range_m) &&
        std::isfinite(params.longitudinal_range_m)))
    throw std::invalid_argument("aps_search_window: search ranges must be finite and non-negative");
  ApsSearchWindow window;
  window.nx = steps_in(params.longitudinal_range_m, params.step_m);
  window.ny = steps_in(params.lateral_range_m, params.step_m);
  window.step_cells = step_cells;
  window.step_m = params.step_m;
  return window;
}

std::vector<double> aps_log_probabilities(const std::vector<float>& z_score_sums, double alpha) {
  std::vector<double> log_p(z_score_sums.size());
  for (size_t k = 0; k < z_score_sums.size(); ++k) log_p[k] = -0.5 * alpha * double(z_score_sums[k]);
  return log_p;
}

bool aps_peak_on_edge(const std::vector<double>& log_p, const ApsSearchWindow& window) {
  const int ox = window.offsets_x(), oy = window.offsets_y();
  const auto best = std::max_element(log_p.begin(), log_p.end()) - log_p.begin();
  const int i = int(best % ox), j = int(best / ox);
  return (window.nx > 0 && (i == 0 || i == ox - 1)) || (window.ny > 0 && (j == 0 || j == oy - 1));
}

double aps_along_margin(const std::vector<double>& log_p, const ApsSearchWindow& window, double separation_m,
                        double prior_sigma_m) {
  const int ox = window.offsets_x(), oy = window.offsets_y();
  std::vector<double> along(size_t(ox), -std::numeric_limits<double>::infinity());
  for (int j = 0; j < oy; ++j)
    for (int i = 0; i < ox; ++i)
      along[size_t(i)] = std::max(along[size_t(i)], log_p[size_t(j) * size_t(ox) + size_t(i)]);
  for (int i = 0; i < ox; ++i) along[size_t(i)] -= 0.5 * std::pow(window.offset(i, 0).x() / prior_sigma_m, 2);
  const int best = int(std::max_element(along.begin(), along.end()) - along.begin());
  auto is_peak = [&](int i) {
    return (i == 0 || along[size_t(i)] >= along[size_t(i - 1)]) &&
           (i == ox - 1 || along[size_t(i)] >= along[size_t(i + 1)]);
  };
  double other = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < ox; ++i)
    if (std::abs(i - best) * window.step_m > separation_m && is_peak(i)) other = std::max(other, along[size_t(i)]);
  return along[size_t(best)] - other;
}

OffsetMoments aps_offset_moments(const std::vector<double>& log_p, const ApsSearchWindow& window) {
  // Relative to the best offset before exponentiating: the raw sums are thousands, exp() would be 0.
  const double best = *std::max_element(log_p.begin(), log_p.end());
  const int ox = window.offsets_x(), oy = window.offsets_y();
  double total = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  for (int j = 0; j < oy; ++j) {
    for (int i = 0; i < ox; ++i) {
      const double p = std::exp(log_p[size_t(j) * size_t(ox) + size_t(i)] - best);
      const Eigen::Vector2d o = window.offset(i, j);
      total += p;
      mean += p * o;
      second += p * o * o.transpose();
    }
  }
  mean /= total;  // Eq. 15-16: centre of mass
  Eigen::Matrix2d covariance = second / total - mean * mean.transpose();
  // A distribution on a grid of steps can put all its mass on one offset; the estimate is still only
  // known to within a step, so add the variance of a uniform spread over one step (step^2 / 12).
  covariance.diagonal().array() += window.step_m * window.step_m / 12.0;
  return {mean, covariance};
}

bool aps_cell_usable(const IntensityCell& s, const ApsParams& params) { return usable(s, params); }

double aps_cell_sigma(const IntensityCell& cell, double min_sigma) { return floored_sigma(cell, min_sigma); }

ApsResult aps_match(const IntensityGrid& S, IntensityMap& map, const ApsParams& params) {
  check_aps_inputs(S, map.header().resolution_m, params);
  const ApsSearchWindow window = aps_search_window(params, S.params.cell_m);
  const CellCounts usable = usable_cells(S, params);
  const MapWindow under_s = map_under_window(S, map, window, usable, params.min_sigma);
  const ZScoreSums sums = z_score_sums(S, under_s, window, params);

  const Eigen::Matrix2d R = rotation(S.pose.yaw);
  const Eigen::Vector2d origin(S.pose.x, S.pose.y);
  ApsResult result;
  result.cells_used = sums.cells_used;
  result.position = origin;
  if (sums.cells_used < params.min_cells) {
    result.covariance = R * uniform_over_window(window) * R.transpose();
    return result;
  }
  const std::vector<double> log_p = aps_log_probabilities(sums.per_offset, params.alpha);  // Eq. 14
  const OffsetMoments moments = aps_offset_moments(log_p, window);                         // Eq. 15-16
  result.ok = true;
  result.peak_on_edge = aps_peak_on_edge(log_p, window);
  result.along_margin =
      aps_along_margin(log_p, window, params.distinct_separation_m, params.prior_longitudinal_sigma_m);
  result.offset_vehicle = moments.mean;
  result.position = origin + R * moments.mean;  // Eq. 17-18, the offset rotated from the vehicle frame
  result.covariance = R * moments.covariance * R.transpose();
  // At the offset nearest the centre of mass.
  const int i = std::clamp(int(std::lround(moments.mean.x() / window.step_m)) + window.nx, 0, window.offsets_x() - 1);
  const int j = std::clamp(int(std::lround(moments.mean.y() / window.step_m)) + window.ny, 0, window.offsets_y() - 1);
  result.yaw_coupling = R * yaw_coupling(S, under_s, window, params, i, j);
  const Eigen::Vector2d uniform = uniform_over_window(window).diagonal();
  for (int k = 0; k < 2; ++k) result.spread_ratio[k] = uniform[k] > 0 ? moments.covariance(k, k) / uniform[k] : 1.0;
  return result;
}

}  // namespace lidarloop
