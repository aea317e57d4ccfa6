// Wide APS over x, y and yaw, coarse to fine. See wide_search.hpp.
//
// Frame: everything is scored in the vehicle frame of the step's prior (S.pose), as aps_match does: the
// map is resampled into windows of that frame's cells (one for the coarse level, one around each
// refined candidate), a yaw rotates S's cells about the vehicle into them, and an offset is whole
// cells. So at yaw zero a fine score is aps_match's.
#include "localizer/wide_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

#include "localizer/cell_counts.hpp"

namespace lidarloop {
namespace {

// Lengths and angles that must come out whole (ranges over steps) are rounded with this tolerance, so
// a range that is a multiple of its step keeps its last step.
constexpr double kStepTolerance = 1e-9;
// S's cell and the map's must be one size; they come from YAML, not from one literal.
constexpr double kLengthTolerance = 1e-6;

int whole_steps(double range, double step) { return static_cast<int>(std::floor(range / step + kStepTolerance)); }

Eigen::Matrix2d rotation(double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

void check_params(const WideApsParams& p) {
  auto finite_non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!finite_non_negative(p.longitudinal_range_m) || !finite_non_negative(p.lateral_range_m) ||
      !finite_non_negative(p.yaw_range_rad))
    throw std::invalid_argument("wide_aps_search: search ranges must be finite and non-negative");
  if (!positive(p.coarse_yaw_step_rad) || !positive(p.fine_yaw_step_rad))
    throw std::invalid_argument("wide_aps_search: yaw steps must be positive numbers");
  if (p.coarse_factor < 1 || p.refine_radius_cells < 1 || p.candidates < 1)
    throw std::invalid_argument("wide_aps_search: coarse_factor, refine_radius_cells and candidates must be >= 1");
  if (!finite_non_negative(p.distinct_separation_m) || p.max_terms_per_step < 1)
    throw std::invalid_argument("wide_aps_search: distinct_separation_m must be >= 0 and max_terms_per_step >= 1");
  if (!positive(p.aps.alpha) || !positive(p.aps.min_sigma))
    throw std::invalid_argument("wide_aps_search: alpha and min_sigma must be positive numbers");
}

void check_grid(const IntensityGrid& S, double map_resolution_m, const WideApsParams& p) {
  const IntensityGridParams& g = S.params;
  if (g.width_cells <= 0 || g.height_cells <= 0 || S.cells.size() != size_t(g.width_cells) * size_t(g.height_cells))
    throw std::invalid_argument("wide_aps_search: grid S has no cells or not w_s * h_s of them");
  if (!(std::fabs(g.cell_m - map_resolution_m) <= kLengthTolerance * map_resolution_m))
    throw std::invalid_argument("wide_aps_search: grid cell size " + std::to_string(g.cell_m) +
                                " m is not the map's resolution " + std::to_string(map_resolution_m) + " m");
  if (g.width_cells % p.coarse_factor != 0 || g.height_cells % p.coarse_factor != 0)
    throw std::invalid_argument("wide_aps_search: grid S's size must be a multiple of coarse_factor");
}

// A cell of S that takes part: its centre in the vehicle frame and its Eq. 14 statistics.
struct SourceCell {
  double x, y;
  float mean, sigma;
};

// One level of the search: S's usable cells, and the map in the vehicle frame's cells of cell_m under
// S shifted by a centre offset (ci, cj) cells and by up to the margins more. Window cell (c, r) is the
// vehicle-frame cell of S's cell (c - margin_x + ci, r - margin_y + cj); offsets are relative to the
// centre.
struct Level {
  double cell_m = 0;
  int s_cols = 0, s_rows = 0;
  int margin_x = 0, margin_y = 0;
  std::vector<SourceCell> cells;  // fine level: S's usable cells
  // Coarse level: S's usable fine cells (vehicle frame) with their Eq. 8 statistics, merged into
  // coarse cells anew at each yaw.
  std::vector<std::pair<Eigen::Vector2d, IntensityMoments>> fine_cells;
  int cols = 0, rows = 0;
  std::vector<float> mean;   // NaN where the map has no data
  std::vector<float> sigma;  // floored standard deviation
  CellCounts missing;        // window cells without map data

  size_t index(int c, int r) const { return size_t(r) * size_t(cols) + size_t(c); }
};

// How far (m) a yaw moves S's farthest cell.
double rotation_reach(const IntensityGrid& S, double yaw) {
  const double half_diagonal =
      0.5 * std::hypot(S.params.width_cells * S.params.cell_m, S.params.height_cells * S.params.cell_m);
  return half_diagonal * std::sin(std::min(std::fabs(yaw), std::numbers::pi / 2));
}

// The map's statistics under the window, read only where a usable cell of S can look: window cell
// (c, r) is reached by S cells [c - 2 margin_x, c] x [r - 2 margin_y, r] (of `usable`, in S's cells
// of this level). read(c, r) returns the statistics of window cell (c, r), if the map has any.
template <class Read>
void read_window(Level& L, const CellCounts& usable, const WideApsParams& p, Read read) {
  L.cols = L.s_cols + 2 * L.margin_x;
  L.rows = L.s_rows + 2 * L.margin_y;
  L.mean.assign(size_t(L.cols) * size_t(L.rows), std::numeric_limits<float>::quiet_NaN());
  L.sigma.assign(L.mean.size(), float(p.aps.min_sigma));
  for (int r = 0; r < L.rows; ++r) {
    const int r0 = std::max(r - 2 * L.margin_y, 0), r1 = std::min(r, L.s_rows - 1);
    if (r0 > r1) continue;
    for (int c = 0; c < L.cols; ++c) {
      const int c0 = std::max(c - 2 * L.margin_x, 0), c1 = std::min(c, L.s_cols - 1);
      if (c0 > c1 || usable.in(c0, r0, c1 - c0 + 1, r1 - r0 + 1) == 0) continue;
      const IntensityMoments m = read(c, r);
      if (m.count == 0) continue;
      L.mean[L.index(c, r)] = float(m.mean);
      L.sigma[L.index(c, r)] = float(aps_cell_sigma(m.to_cell(), p.aps.min_sigma));
    }
  }
  L.missing = CellCounts(L.cols, L.rows, [&](int c, int r) { return std::isnan(L.mean[L.index(c, r)]); });
}

// The map cell (Eq. 8 statistics) at fine vehicle-frame cell (i, j) of S's grid.
struct MapReader {
  const IntensityGrid& S;
  IntensityMap& map;
  Eigen::Matrix2d R = rotation(S.pose.yaw);
  Eigen::Vector2d origin{S.pose.x, S.pose.y};

  IntensityMoments operator()(int i, int j) const {
    const std::optional<IntensityCell> m = map.cell(origin + R * S.cell_centre(i, j));
    return m ? IntensityMoments::from_cell(*m) : IntensityMoments{};
  }
};

// The fine level around a candidate at (ci, cj) cells: margins for boxes of +-reach cells and S
// rotated by up to |yaw| plus the refinement's yaws.
Level fine_level(const IntensityGrid& S, IntensityMap& map, const WideApsParams& p, int ci, int cj, double yaw,
                 int reach) {
  Level L;
  L.cell_m = S.params.cell_m;
  L.s_cols = S.params.width_cells;
  L.s_rows = S.params.height_cells;
  const double turn = std::fabs(yaw) + 0.5 * p.coarse_yaw_step_rad;
  L.margin_x = L.margin_y = reach + int(std::ceil(rotation_reach(S, turn) / L.cell_m)) + 1;  // +1: rounding
  for (int r = 0; r < L.s_rows; ++r)
    for (int c = 0; c < L.s_cols; ++c) {
      const IntensityCell& s = S.cells[size_t(r) * size_t(L.s_cols) + size_t(c)];
      if (!aps_cell_usable(s, p.aps)) continue;
      const Eigen::Vector2d v = S.cell_centre(c, r);
      L.cells.push_back({v.x(), v.y(), s.mean, float(aps_cell_sigma(s, p.aps.min_sigma))});
    }
  const CellCounts usable(L.s_cols, L.s_rows, [&](int c, int r) {
    return aps_cell_usable(S.cells[size_t(r) * size_t(L.s_cols) + size_t(c)], p.aps);
  });
  const MapReader reader{S, map};
  read_window(L, usable, p, [&](int c, int r) { return reader(c - L.margin_x + ci, r - L.margin_y + cj); });
  return L;
}

// The coarse level over the whole search: the map merged into f x f blocks of fine cells by Eq. 8's
// statistics (Chan's exact combination), so a coarse cell has the count, mean and spread of every
// intensity its fine cells saw; S's fine cells kept for coarse_s_at.
Level coarse_level(const IntensityGrid& S, IntensityMap& map, const WideApsParams& p) {
  const int f = p.coarse_factor;
  Level L;
  L.cell_m = S.params.cell_m * f;
  L.s_cols = S.params.width_cells / f;
  L.s_rows = S.params.height_cells / f;
  const double rotation_m = rotation_reach(S, p.yaw_range_rad + 0.5 * p.coarse_yaw_step_rad);
  L.margin_x = int(std::ceil((p.longitudinal_range_m + rotation_m) / L.cell_m)) + 1;
  L.margin_y = int(std::ceil((p.lateral_range_m + rotation_m) / L.cell_m)) + 1;
  std::vector<char> usable(size_t(L.s_cols) * size_t(L.s_rows), 0);  // blocks with a usable fine cell
  for (int r = 0; r < S.params.height_cells; ++r)
    for (int c = 0; c < S.params.width_cells; ++c) {
      const IntensityCell& s = S.cells[size_t(r) * size_t(S.params.width_cells) + size_t(c)];
      if (!aps_cell_usable(s, p.aps)) continue;
      usable[size_t(r / f) * size_t(L.s_cols) + size_t(c / f)] = 1;
      L.fine_cells.emplace_back(S.cell_centre(c, r), IntensityMoments::from_cell(s));
    }
  const CellCounts usable_counts(L.s_cols, L.s_rows,
                                 [&](int c, int r) { return usable[size_t(r) * size_t(L.s_cols) + size_t(c)] != 0; });
  const MapReader reader{S, map};
  read_window(L, usable_counts, p, [&](int bc, int br) {
    IntensityMoments block;
    for (int j = (br - L.margin_y) * f; j < (br - L.margin_y + 1) * f; ++j)
      for (int i = (bc - L.margin_x) * f; i < (bc - L.margin_x + 1) * f; ++i) block.merge(reader(i, j));
    return block;
  });
  return L;
}

// Offsets [i0, i0 + ni) x [j0, j0 + nj) in cells of the level, relative to its centre.
struct OffsetBox {
  int i0, ni, j0, nj;
  int count() const { return ni * nj; }
};

// Where each cell of S falls in the window at each yaw (rotated about the vehicle, offset zero), and
// which cells take part: those with map data under them at every offset of `box` and every yaw, so
// all poses scored with these placements are scored on the same cells (aps_match's rule).
struct Placements {
  std::vector<double> yaws;
  std::vector<size_t> zero;  // [yaw * cells + cell]: window index at offset zero
  std::vector<char> takes_part;
  int cells = 0;
};

Placements place(const Level& L, std::vector<double> yaws, const OffsetBox& box) {
  const size_t n = L.cells.size();
  Placements pl;
  pl.yaws = std::move(yaws);
  pl.zero.assign(n * pl.yaws.size(), 0);
  pl.takes_part.assign(n, 1);
  for (size_t k = 0; k < pl.yaws.size(); ++k) {
    const double c = std::cos(pl.yaws[k]), s = std::sin(pl.yaws[k]);
    for (size_t q = 0; q < n; ++q) {
      if (!pl.takes_part[q]) continue;
      const SourceCell& cell = L.cells[q];
      const int col = int(std::floor((c * cell.x - s * cell.y) / L.cell_m + 0.5 * L.s_cols)) + L.margin_x;
      const int row = int(std::floor((s * cell.x + c * cell.y) / L.cell_m + 0.5 * L.s_rows)) + L.margin_y;
      if (col + box.i0 < 0 || row + box.j0 < 0 || col + box.i0 + box.ni > L.cols || row + box.j0 + box.nj > L.rows ||
          L.missing.in(col + box.i0, row + box.j0, box.ni, box.nj) != 0) {
        pl.takes_part[q] = 0;
        continue;
      }
      pl.zero[k * n + q] = L.index(col, row);
    }
  }
  pl.cells = int(std::count(pl.takes_part.begin(), pl.takes_part.end(), 1));
  return pl;
}

// Eq. 14's exponent without -alpha/2 for the offsets of `box` (inside the placements' box) at yaw k:
// sums[j * ni + i]. The offsets innermost, as in aps_match, so the loop vectorises.
std::vector<float> z_score_sums(const Level& L, const std::vector<SourceCell>& cells, const Placements& pl, size_t k,
                                const OffsetBox& box) {
  const size_t n = cells.size();
  std::vector<float> sums(size_t(box.count()), 0.0f);
  const float* map_mean = L.mean.data();
  const float* map_sigma = L.sigma.data();
  const long corner = long(box.j0) * L.cols + box.i0;
  for (size_t q = 0; q < n; ++q) {
    if (!pl.takes_part[q]) continue;
    const float s_r = cells[q].mean, s_sigma = cells[q].sigma;
    for (int j = 0; j < box.nj; ++j) {
      const size_t base = size_t(long(pl.zero[k * n + q]) + corner + long(j) * L.cols);
      float* acc = &sums[size_t(j) * size_t(box.ni)];
      for (int i = 0; i < box.ni; ++i) {
        const float d = map_mean[base + size_t(i)] - s_r, e = map_sigma[base + size_t(i)] + s_sigma;
        acc[i] += d * d / (e * e);
      }
    }
  }
  return sums;
}

// S turned by `yaw` at the coarse level: its usable fine cells rotated about the vehicle and merged
// into the coarse window's cells (S has cells, not points: a fine cell moves whole). Rebuilt at each
// yaw, so the coarse cells' mixtures of paint and asphalt turn with S, which moving whole coarse cells
// would not do below a cell's width of motion. The placements are for `box`.
struct CoarseS {
  std::vector<SourceCell> cells;
  Placements placements;
};

CoarseS coarse_s_at(const Level& C, double yaw, const OffsetBox& box, double min_sigma) {
  std::vector<IntensityMoments> merged(size_t(C.cols) * size_t(C.rows));
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (const auto& [v, stats] : C.fine_cells) {
    const int col = int(std::floor((c * v.x() - s * v.y()) / C.cell_m + 0.5 * C.s_cols)) + C.margin_x;
    const int row = int(std::floor((s * v.x() + c * v.y()) / C.cell_m + 0.5 * C.s_rows)) + C.margin_y;
    if (col >= 0 && row >= 0 && col < C.cols && row < C.rows) merged[C.index(col, row)].merge(stats);
  }
  CoarseS out;
  out.placements.yaws = {yaw};
  for (int row = 0; row < C.rows; ++row)
    for (int col = 0; col < C.cols; ++col) {
      const IntensityMoments& m = merged[C.index(col, row)];
      if (m.count == 0) continue;
      const bool on_map = col + box.i0 >= 0 && row + box.j0 >= 0 && col + box.i0 + box.ni <= C.cols &&
                          row + box.j0 + box.nj <= C.rows &&
                          C.missing.in(col + box.i0, row + box.j0, box.ni, box.nj) == 0;
      out.cells.push_back({0, 0, float(m.mean), float(aps_cell_sigma(m.to_cell(), min_sigma))});
      out.placements.zero.push_back(C.index(col, row));
      out.placements.takes_part.push_back(on_map ? 1 : 0);
      out.placements.cells += on_map ? 1 : 0;
    }
  return out;
}

// The correction of `prior` that puts the car at vehicle-frame offset (x, y) and yaw offset.
Pose2d correction_at(const Pose2d& prior, double x, double y, double yaw) {
  return prior.compose(Pose2d{x, y, yaw}).compose(prior.inverse());
}

double distance(const Pose2d& a, const Pose2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

int coarse_slices(const WideApsParams& p) { return 2 * whole_steps(p.yaw_range_rad, p.coarse_yaw_step_rad) + 1; }

// The fine yaws around a coarse one cover half a coarse step either side.
int fine_yaw_steps(const WideApsParams& p) {
  return static_cast<int>(std::ceil(0.5 * p.coarse_yaw_step_rad / p.fine_yaw_step_rad - kStepTolerance));
}

OffsetBox coarse_box(const WideApsParams& p, double coarse_m) {
  const int nx = whole_steps(p.longitudinal_range_m, coarse_m), ny = whole_steps(p.lateral_range_m, coarse_m);
  return {-nx, 2 * nx + 1, -ny, 2 * ny + 1};
}

OffsetBox square(int ci, int cj, int radius) { return {ci - radius, 2 * radius + 1, cj - radius, 2 * radius + 1}; }

// The poses one fine refinement usually scores, to budget it: offsets at the candidate's yaw and at the
// leading candidate's, yaws around the better peak at +-1 cell, and offsets at the best yaw (a
// re-centring adds a box).
int64_t refine_offsets(const WideApsParams& p) {
  const int64_t box = int64_t(2 * p.refine_radius_cells + 1) * (2 * p.refine_radius_cells + 1);
  return 3 * box + 9 * (2 * fine_yaw_steps(p) + 1);
}

// The index of the largest value.
size_t argmax(const std::vector<double>& v) { return size_t(std::max_element(v.begin(), v.end()) - v.begin()); }

// One coarse yaw slice: its local maxima over the offsets join the pool, with their log P per cell (the
// slices' cells differ a little, S's turn moves some on or off the map). Returns the cells used.
int coarse_slice(const Level& C, const OffsetBox& box, double yaw, const Pose2d& prior, const WideApsParams& params,
                 std::vector<WideApsCandidate>& pool) {
  const CoarseS S = coarse_s_at(C, yaw, box, params.aps.min_sigma);
  const Placements& pl = S.placements;
  if (pl.cells < params.min_coarse_cells) return pl.cells;
  const std::vector<float> sums = z_score_sums(C, S.cells, pl, 0, box);
  const auto at = [&](int i, int j) { return sums[size_t(j) * size_t(box.ni) + size_t(i)]; };
  for (int j = 0; j < box.nj; ++j)
    for (int i = 0; i < box.ni; ++i) {
      bool peak = true;
      for (int dj = -1; dj <= 1 && peak; ++dj)
        for (int di = -1; di <= 1 && peak; ++di) {
          const int ii = i + di, jj = j + dj;
          if ((di || dj) && ii >= 0 && jj >= 0 && ii < box.ni && jj < box.nj && at(ii, jj) < at(i, j)) peak = false;
        }
      if (!peak) continue;
      WideApsCandidate c;
      c.correction = correction_at(prior, (i + box.i0) * C.cell_m, (j + box.j0) * C.cell_m, yaw);
      c.log_p_per_cell = -0.5 * params.aps.alpha * at(i, j) / pl.cells;
      c.cells = pl.cells;
      pool.push_back(c);
    }
  return pl.cells;
}

// The pool's best, pairwise distinct (compared at this step's prior), to refine.
std::vector<WideApsCandidate> distinct_best(std::vector<WideApsCandidate> pool, const Pose2d& prior,
                                            const WideApsParams& params) {
  std::stable_sort(pool.begin(), pool.end(), [](const WideApsCandidate& a, const WideApsCandidate& b) {
    return a.log_p_per_cell > b.log_p_per_cell;
  });
  std::vector<WideApsCandidate> chosen;
  for (const WideApsCandidate& c : pool) {
    if (int(chosen.size()) >= params.candidates) break;
    const Pose2d pose = c.correction.compose(prior);
    const bool distinct = std::all_of(chosen.begin(), chosen.end(), [&](const WideApsCandidate& o) {
      return distance(pose, o.correction.compose(prior)) > params.distinct_separation_m;
    });
    if (distinct) chosen.push_back(c);
  }
  return chosen;
}

// One candidate at the map's resolution: Eq. 14 over +-R cells at its yaw (re-centred once if the
// peak is on the box's edge), over +-K fine yaw steps at +-1 cell around that peak, and over +-R cells
// at the best yaw; then Eq. 15-16's moments at the best yaw and the yaw distribution.
// The work a unit did: poses scored and z-score terms summed.
struct Work {
  int64_t offsets = 0, terms = 0;
};

Work refine(WideApsCandidate& cand, const IntensityGrid& S, IntensityMap& map, const WideApsParams& p,
            std::optional<double> lead_yaw) {
  Work work;
  const Pose2d& prior = S.pose;
  const Pose2d b = relative(prior, cand.correction.compose(prior));  // offset and yaw, vehicle frame
  const int R = p.refine_radius_cells, K = fine_yaw_steps(p);
  const int ci = int(std::lround(b.x / S.params.cell_m)), cj = int(std::lround(b.y / S.params.cell_m));
  // The boxes below reach 3R + 1 cells from the centre (a re-centring by R, then +-(R + 1) around the
  // peak), at this candidate's yaws or the leading one's.
  const double turn = std::max(std::fabs(b.yaw), lead_yaw ? std::fabs(*lead_yaw) : 0.0);
  const Level F = fine_level(S, map, p, ci, cj, turn, 3 * R + 1);
  const double alpha = p.aps.alpha;
  // The peak of a box at yaw k of the placements: (offset i, offset j) relative to the centre.
  // Eq. 14 in logs over a box at yaw k of the placements, counted.
  const auto log_probabilities = [&](const Placements& pl, size_t k, const OffsetBox& box) {
    work.offsets += box.count();
    work.terms += int64_t(pl.cells) * box.count();
    return aps_log_probabilities(z_score_sums(F, F.cells, pl, k, box), alpha);
  };
  const auto peak = [&](const Placements& pl, size_t k, const OffsetBox& box, std::vector<double>& log_p) {
    log_p = log_probabilities(pl, k, box);
    const size_t best = argmax(log_p);
    return std::pair<int, int>{box.i0 + int(best) % box.ni, box.j0 + int(best) / box.ni};
  };
  const auto refused = [&](const Placements& pl) {
    cand.cells = pl.cells;
    if (pl.cells >= p.aps.min_cells) return false;
    cand.log_p_per_cell = -std::numeric_limits<double>::infinity();
    return true;
  };
  // Offsets at a yaw, re-centred once if the peak is on the box's edge: the peak, and its log P per
  // cell. Each box is placed on its own cells: the cells-under-map rule over a larger box would drop
  // more of S.
  struct Peak {
    int i, j;
    double log_p_per_cell;
  };
  const auto offsets_at = [&](double yaw) -> std::optional<Peak> {
    std::vector<double> log_p;
    const Placements at_yaw = place(F, {yaw}, square(0, 0, R));
    if (refused(at_yaw)) return std::nullopt;
    auto [i, j] = peak(at_yaw, 0, square(0, 0, R), log_p);
    int cells = at_yaw.cells;
    if (std::abs(i) == R || std::abs(j) == R) {
      const Placements moved = place(F, {yaw}, square(i, j, R));
      if (refused(moved)) return std::nullopt;
      std::tie(i, j) = peak(moved, 0, square(i, j, R), log_p);
      cells = moved.cells;
    }
    return Peak{i, j, *std::max_element(log_p.begin(), log_p.end()) / cells};
  };
  double yaw = b.yaw;
  std::optional<Peak> found = offsets_at(yaw);
  // Periodic paint's other peaks are translations of the leading one, at its yaw; the coarse level may
  // have put them a step of yaw off, out of the refinement's reach, and the margin would then overstate
  // how distinct the best is.
  if (lead_yaw && std::fabs(*lead_yaw - b.yaw) > 0.5 * p.fine_yaw_step_rad) {
    const std::optional<Peak> at_lead = offsets_at(*lead_yaw);
    if (at_lead && (!found || at_lead->log_p_per_cell > found->log_p_per_cell)) found = at_lead, yaw = *lead_yaw;
  }
  if (!found) return work;
  const int i = found->i, j = found->j;
  // The yaws and the final offsets on one set of cells, so their probabilities compare.
  std::vector<double> yaws;
  for (int k = -K; k <= K; ++k) yaws.push_back(yaw + k * p.fine_yaw_step_rad);
  const Placements pl = place(F, yaws, square(i, j, R + 1));
  if (refused(pl)) return work;
  // Yaws at +-1 cell around the peak: the yaw distribution, each yaw's P summed over its offsets.
  const OffsetBox around = square(i, j, 1);
  std::vector<std::vector<double>> by_yaw(yaws.size());
  double best_log_p = -std::numeric_limits<double>::infinity();
  size_t best_yaw = size_t(K);
  for (size_t k = 0; k < yaws.size(); ++k) {
    by_yaw[k] = log_probabilities(pl, k, around);
    const double top = *std::max_element(by_yaw[k].begin(), by_yaw[k].end());
    if (top > best_log_p) best_log_p = top, best_yaw = k;
  }
  double total = 0, mean = 0, second = 0;
  for (size_t k = 0; k < yaws.size(); ++k)
    for (double lp : by_yaw[k]) {
      const double w = std::exp(lp - best_log_p);
      total += w;
      mean += w * yaws[k];
      second += w * yaws[k] * yaws[k];
    }
  mean /= total;
  cand.yaw_variance = std::max(second / total - mean * mean, 0.0) + p.fine_yaw_step_rad * p.fine_yaw_step_rad / 12;
  // Eq. 15-16 at the best yaw, around its peak.
  const size_t around_best = argmax(by_yaw[best_yaw]);
  const int bi = around.i0 + int(around_best) % around.ni, bj = around.j0 + int(around_best) / around.ni;
  const std::vector<double> log_p = log_probabilities(pl, best_yaw, square(bi, bj, R));
  const OffsetMoments m = aps_offset_moments(log_p, ApsSearchWindow{R, R, 1, F.cell_m});
  cand.offset_covariance = m.covariance;
  cand.correction = correction_at(prior, (ci + bi) * F.cell_m + m.mean.x(), (cj + bj) * F.cell_m + m.mean.y(), mean);
  cand.log_p_per_cell = *std::max_element(log_p.begin(), log_p.end()) / pl.cells;
  return work;
}

// The verdict: every refined candidate's pose scored again on this step's S, on the cells of S with map
// data under them at all of those poses, so that the candidates compare on one S and one set of cells
// even when they were refined on different scans (whose S differ in content, not only in noise).
Work verdict(std::vector<WideApsCandidate>& refined, const IntensityGrid& S, IntensityMap& map,
             const WideApsParams& p) {
  std::vector<WideApsCandidate*> live;
  std::vector<PoseApplier> poses;
  for (WideApsCandidate& c : refined)
    if (std::isfinite(c.log_p_per_cell)) live.push_back(&c), poses.emplace_back(c.correction.compose(S.pose));
  std::vector<double> sums(live.size(), 0.0), terms(live.size());
  int cells = 0;
  for (int r = 0; r < S.params.height_cells; ++r)
    for (int c = 0; c < S.params.width_cells; ++c) {
      const IntensityCell& s = S.cells[size_t(r) * size_t(S.params.width_cells) + size_t(c)];
      if (!aps_cell_usable(s, p.aps)) continue;
      const Eigen::Vector2d v = S.cell_centre(c, r);
      const double s_sigma = aps_cell_sigma(s, p.aps.min_sigma);
      bool under_all = true;
      for (size_t k = 0; k < live.size() && under_all; ++k) {
        const std::optional<IntensityCell> m = map.cell(poses[k](v));
        under_all = m && m->count > 0;
        if (!under_all) break;
        const double d = m->mean - s.mean, e = aps_cell_sigma(*m, p.aps.min_sigma) + s_sigma;
        terms[k] = d * d / (e * e);
      }
      if (!under_all) continue;
      ++cells;
      for (size_t k = 0; k < live.size(); ++k) sums[k] += terms[k];
    }
  for (size_t k = 0; k < live.size(); ++k) {
    live[k]->cells = cells;
    live[k]->log_p_per_cell =
        cells >= p.aps.min_cells ? -0.5 * p.aps.alpha * sums[k] / cells : -std::numeric_limits<double>::infinity();
  }
  return {int64_t(live.size()), int64_t(live.size()) * cells};
}

// The best refined candidate, and the best farther than distinct_separation_m from it, at `prior`.
void summarise(const std::vector<WideApsCandidate>& refined, const Pose2d& prior, const WideApsParams& p,
               double coarse_m, WideApsResult& r) {
  const auto best = std::max_element(
      refined.begin(), refined.end(),
      [](const WideApsCandidate& a, const WideApsCandidate& b) { return a.log_p_per_cell < b.log_p_per_cell; });
  if (best == refined.end() || !std::isfinite(best->log_p_per_cell)) return;
  const Pose2d pose = best->correction.compose(prior);
  const WideApsCandidate* runner_up = nullptr;
  for (const WideApsCandidate& c : refined)
    if (std::isfinite(c.log_p_per_cell) && distance(c.correction.compose(prior), pose) > p.distinct_separation_m &&
        (!runner_up || c.log_p_per_cell > runner_up->log_p_per_cell))
      runner_up = &c;
  r.ok = true;
  r.pose = pose;
  r.correction = best->correction;
  r.cells_used = best->cells;
  r.log_p = best->log_p_per_cell * best->cells;
  r.margin = runner_up ? (best->log_p_per_cell - runner_up->log_p_per_cell) * best->cells
                       : std::numeric_limits<double>::infinity();
  if (runner_up) r.runner_up = runner_up->correction.compose(prior);
  r.places.clear();
  for (const WideApsCandidate& c : refined)
    if (std::isfinite(c.log_p_per_cell))
      r.places.push_back({c.correction.compose(prior), c.log_p_per_cell * best->cells});
  const Eigen::Matrix2d Rp = rotation(prior.yaw);
  r.covariance.setZero();
  r.covariance.topLeftCorner<2, 2>() = Rp * best->offset_covariance * Rp.transpose();
  r.covariance(2, 2) = best->yaw_variance;
  const Pose2d b = relative(prior, pose);
  r.peak_on_edge = std::fabs(b.x) > p.longitudinal_range_m - 0.5 * coarse_m ||
                   std::fabs(b.y) > p.lateral_range_m - 0.5 * coarse_m ||
                   std::fabs(b.yaw) > p.yaw_range_rad - 0.5 * p.coarse_yaw_step_rad;
}

}  // namespace

WideApsSearch::WideApsSearch(const WideApsParams& params) : params_(params) { check_params(params_); }

void WideApsSearch::restart() { *this = WideApsSearch(params_); }

void WideApsSearch::step(const IntensityGrid& S, IntensityMap& map) {
  if (done()) return;
  check_grid(S, map.header().resolution_m, params_);
  const WideApsParams& p = params_;
  const Pose2d& prior = S.pose;
  int64_t spent = 0;
  bool any = false;
  // Within budget for a unit of this cost? A step does at least one.
  const auto afford = [&](int64_t cost) {
    if (any && spent + cost > p.max_terms_per_step) return false;
    spent += cost;
    any = true;
    return true;
  };

  if (phase_ == Phase::coarse) {
    const Level C = coarse_level(S, map, p);
    const int n = coarse_slices(p);
    const OffsetBox box = coarse_box(p, C.cell_m);
    // About the coarse cells S covers: its fine cells over a coarse cell's.
    const int64_t cells = int64_t(C.fine_cells.size()) / (int64_t(p.coarse_factor) * p.coarse_factor) + 1;
    while (next_unit_ < n && afford(cells * box.count())) {
      const double yaw = (next_unit_++ - n / 2) * p.coarse_yaw_step_rad;
      terms_ += int64_t(coarse_slice(C, box, yaw, prior, p, pool_)) * box.count();
      offsets_ += box.count();
    }
    if (next_unit_ == n) {
      refined_ = distinct_best(std::move(pool_), prior, p);
      pool_.clear();
      phase_ = refined_.empty() ? Phase::done : Phase::fine;
      next_unit_ = 0;
      // The step that ends the coarse phase refines nothing: building the coarse level reads the map
      // over the whole window, which the terms do not count, and with a refinement after it one step
      // took 17 ms of a cold start's scan (bench localizer, timed by hand around the step; the scans
      // with a wide search went from 26-28 ms to 14-15 ms at p99).
      if (phase_ == Phase::fine) {
        result_.offsets_evaluated = offsets_;
        result_.terms_evaluated = terms_;
        return;
      }
    }
  }
  if (phase_ == Phase::fine) {
    const int64_t cost = int64_t(std::count_if(S.cells.begin(), S.cells.end(),
                                               [&](const IntensityCell& c) { return aps_cell_usable(c, p.aps); })) *
                         refine_offsets(p);
    while (next_unit_ < int(refined_.size()) && afford(cost)) {
      WideApsCandidate& c = refined_[size_t(next_unit_)];
      const Work w =
          refine(c, S, map, p, next_unit_ > 0 ? std::optional<double>(refined_.front().correction.yaw) : std::nullopt);
      ++next_unit_;
      offsets_ += w.offsets;
      terms_ += w.terms;
    }
    if (next_unit_ == int(refined_.size())) phase_ = Phase::done;
  }
  result_.offsets_evaluated = offsets_;
  result_.terms_evaluated = terms_;
  if (!done()) return;
  const Work w = verdict(refined_, S, map, p);
  result_.offsets_evaluated = offsets_ += w.offsets;
  result_.terms_evaluated = terms_ += w.terms;
  summarise(refined_, prior, p, p.coarse_factor * S.params.cell_m, result_);
}

WideApsResult wide_aps_search(const IntensityGrid& S, IntensityMap& map, const WideApsParams& params) {
  WideApsParams unlimited = params;
  unlimited.max_terms_per_step = std::numeric_limits<int64_t>::max();
  WideApsSearch search(unlimited);
  while (!search.done()) search.step(S, map);  // two steps: the coarse phase ends one
  return search.result();
}

}  // namespace lidarloop
