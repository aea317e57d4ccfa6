#pragma once
// Intensity feature matching (the paper's sections 2.2.2 and 3.2): the ground points of one scan are
// binned into a vehicle-centred grid S of running intensity statistics (Eq. 8), and S is matched
// against the intensity layer of the map by APS (Levinson & Thrun, the paper's ref. [22]): every
// offset of a small search window gets a probability (Eq. 14), and the centre of mass of that
// distribution is the position estimate (Eq. 15-18).
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"
#include "localizer/intensity_map.hpp"

namespace lidarloop {

// Grid S (Table I: w_s = h_s = 200). Its cells must be the map's cells, so that the search can shift
// S by whole cells; aps_match checks this.
struct IntensityGridParams {
  int width_cells = 200;   // w_s: along x (forward)
  int height_cells = 200;  // h_s: along y (left)
  double cell_m = 0.2;
  // Beyond the paper: only points this close to the ground plane go into S (m, either side). Points
  // up to d_sigma = 0.5 m above it are not obstacles, but they are not road paint either: a car's
  // sill, a coach's skirt and wheels. They move with the traffic, and a bright one riding beside the
  // car matches a crosswalk stripe the same way scan after scan (it dragged APS 8 m in bus_occlusion).
  double max_height = 0.15;
  // Beyond the paper: S holds the ground of this scan and the frames - 1 before it, moved by odometry
  // as Eq. 4-5 move the curbs, with the same n (intensity_accumulator.hpp).
  int frames = 5;
  // Beyond the paper: ground points within this distance (m) of an obstacle point (x-y) stay out of S,
  // as the paper keeps curbs within d_o of obstacles out of the curb features (Table I's d_o). A car's
  // tyres, sills and a coach's skirt come within max_height of the road, and their returns are no
  // paint: between parked rows they dragged APS 0.4 m across and 1.8 m along (gps_jump_parked), and kept
  // cold_start_parked's error over 0.3 m for 11.5 s (1.0 s without them). 0: keep them.
  double obstacle_distance = 0.5;
  // ... but only frames since which the car has turned less than this (deg): Eq. 19's kinematic
  // odometry knows no tyre slip, so in a bend it misplaces the older frames' paint. Measured on
  // closed_loop_campus's bends before the obstacle distance above existed (misleading frames /
  // longitudinal RMSE, one seed): 0.5 deg 2 / 0.086 m, 1 deg 15 / 0.120 m, 2 deg 10 / 0.083 m, no limit
  // 37 / 0.147 m, one scan (the paper) 10 / 0.118 m.
  double max_turn_deg = 0.5;
};

// Row-major, in the vehicle frame: x forward along the columns, y left along the rows, the vehicle at
// the centre of the grid (cell (c, r) spans x in [(c - w/2) cell, (c + 1 - w/2) cell), likewise y).
struct IntensityGrid {
  Pose2d pose;  // the local pose the grid was built at (the prior of the match)
  IntensityGridParams params;
  std::vector<IntensityCell> cells;
  // How many times more cells take part in Eq. 14 than the newest scan's alone would give (>= 1; 1 for
  // one scan): S of several scans (IntensityGridParams::frames) has more cells over the same stretch of
  // paint, and Eq. 14's alpha was set for one scan's. Its product grows that many times more confident
  // without the match being that many times more accurate, so the caller widens APS's covariance by
  // this (measured on closed_loop_campus: longitudinal NEES 3.1 with one scan, 6.8 with five unwidened).
  double redundancy = 1.0;
  // The car turned more than IntensityGridParams::max_turn_deg since the previous scan: S is this scan's
  // alone, and its paint is seen across a bend, where APS errs differently (see Localizer's APS scales).
  bool turning = false;

  // Throws std::out_of_range outside the grid.
  const IntensityCell& at(int col, int row) const;
  // Centre of cell (col, row) in the vehicle frame.
  Eigen::Vector2d cell_centre(int col, int row) const;
};

// The row-major index of the cell of S (of these params) a vehicle-frame point falls in; nullopt off the
// grid or not finite.
std::optional<size_t> intensity_cell_index(const IntensityGridParams& params, const Eigen::Vector2d& point_vehicle);

// For each of points[indices] (vehicle frame; z is ignored), in order, whether its cell of S is marked
// (1) in `marked` (row-major, one entry per cell of S, as cells_near_obstacles gives): what
// intensity_cell_index would say for each, for a whole scan at once. Points off the grid are not (0).
std::vector<char> in_marked_cells(const IntensityGridParams& params, const std::vector<char>& marked,
                                  const std::vector<Eigen::Vector3d>& points, const std::vector<size_t>& indices);

// Which cells of S (row-major, 1 = yes) have their centre within params.obstacle_distance of an obstacle
// point (vehicle frame, x-y); all 0 when it is 0.
std::vector<char> cells_near_obstacles(const std::vector<Eigen::Vector2d>& obstacles_vehicle,
                                       const IntensityGridParams& params);

// Bins ground points (vehicle frame; z is ignored) with their intensities into S by Eq. 8. Points off
// the grid or not finite are skipped. Throws std::invalid_argument for mismatched sizes or bad params.
IntensityGrid build_intensity_grid(const std::vector<Eigen::Vector3d>& ground_points_vehicle,
                                   const std::vector<double>& intensities, const Pose2d& pose,
                                   const IntensityGridParams& params = {});

// The same point by point, for points that are not in one vector (intensity_accumulator.hpp's frames).
// Eq. 8's statistics are kept as sums until grid() (a hundred thousand points a scan).
class IntensityGridBuilder {
 public:
  // Throws std::invalid_argument for bad params.
  IntensityGridBuilder(const Pose2d& pose, const IntensityGridParams& params);
  // False, and nothing done, if the point is off the grid or not finite.
  bool add(const Eigen::Vector2d& point_vehicle, double intensity);
  // Many at once; throws std::invalid_argument for mismatched sizes.
  void add(const std::vector<Eigen::Vector2d>& points_vehicle, const std::vector<double>& intensities);
  // Cells holding more than `points` points so far (APS's usable cells for points = n_e).
  long cells_with_more_than(uint32_t points) const;
  IntensityGrid grid() const;

 private:
  Pose2d pose_;
  IntensityGridParams params_;
  // A cell's sums side by side: points land on cells in firing order, all over S, and one cache line
  // per point is a third of the misses of three arrays.
  struct Sums {
    double sum = 0, sum_sq = 0;
    uint32_t count = 0;
  };
  std::vector<Sums> cells_;
};

struct ApsParams {
  double lateral_range_m = 1.0;       // section 3.2: +-1 m across the road (curbs fix the lateral)
  double longitudinal_range_m = 3.0;  // section 3.2: +-3 m along it
  double step_m = 0.2;                // search step; a whole number of map cells (the paper: one cell)
  // Eq. 14's exponent. The cells of S are not independent (neighbouring cells see the same paint,
  // map and scan errors are correlated), so the plain product is far too confident; alpha < 1 tempers
  // it, as in APS. The paper gives no value; 0.5 keeps the peak on features while leaving a
  // featureless road broad (0.2-0.35 were tried on the scenario suite: better on the busy junction of
  // dynamic_campus, worse beside the coach of bus_occlusion).
  double alpha = 0.5;
  int min_count = 3;  // n_e: only cells of S with S_n > n_e take part (fewer points: mean too noisy)
  // Floor on the standard deviations of Eq. 14 (intensity counts). A cell hit by one point, or by
  // points of equal intensity, has zero variance; without a floor one such cell would make the
  // denominator vanish and decide the whole product.
  double min_sigma = 1.0;
  int min_cells = 50;  // fewer usable cells than this: no estimate (ok = false)
  // Two peaks of the distribution along the road closer than this are one (m): the wide search's
  // distinct_separation_m (wide_search.hpp), below the 3 m and more at which dashes repeat.
  double distinct_separation_m = 1.5;
  // The prior's doubt along the road (1 sigma, m), counted in ApsResult::along_margin: the window is
  // centred on the prior, and an offset x along the road is exp(-x^2 / 2 sigma^2) less likely before
  // the paint is seen. Infinite: not counted.
  double prior_longitudinal_sigma_m = std::numeric_limits<double>::infinity();
};

struct ApsResult {
  bool ok = false;  // false: too few usable cells; the caller must not use the estimate
  // (longitudinal, lateral) offset x_o, y_o of Eq. 15-16, vehicle frame (m). Always inside the search
  // window: a larger error cannot be recovered.
  Eigen::Vector2d offset_vehicle = Eigen::Vector2d::Zero();
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // Eq. 17-18: corrected position, local frame
  // Covariance of P over the offsets (plus the step's quantisation), local frame (m^2): the
  // observation noise for the Kalman filter. When !ok: that of a uniform spread over the window.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  // (longitudinal, lateral): the variance of P on each axis over that of a uniform spread over the
  // window's extent on it; near 1 the match says nothing on that axis. 1 for an axis not searched.
  Eigen::Vector2d spread_ratio = Eigen::Vector2d::Ones();
  int cells_used = 0;  // cells of S that entered Eq. 14
  // How far the match moves per radian of error in the prior's heading (local frame, m/rad). APS
  // searches x and y at the prior's yaw: S turned by an error e about the car moves its paint by e
  // times each cell's distance, and the best offset follows by about yaw_coupling * e. The Lucas-Kanade
  // estimate at the best offset: the cells' rotation field projected on the map's intensity gradients,
  // each weighted by Eq. 14's z-score denominator. Zero when not ok.
  Eigen::Vector2d yaw_coupling = Eigen::Vector2d::Zero();
  // The most probable offset lies on the window's border: the true one may well be outside, and the
  // centroid is then pulled towards the middle of a window that does not contain it.
  bool peak_on_edge = false;
  // How far the best offset along the road beats the best other peak along it (aps_along_margin): Eq.
  // 14's log P with the prior along the road. Dashed lines repeat, and a stretch of road with nothing but lines gives a
  // distribution of noise whose highest spike is still narrow; only the margin tells them from a true peak. +inf when
  // no other peak lies in the window.
  double along_margin = std::numeric_limits<double>::infinity();
};

// APS over the window of offsets around S.pose. A cell of S takes part only if S_n > n_e and the map
// has data under it at every offset of the window, so every offset is scored on the same cells (an
// offset that moved S off the map would otherwise lose penalty terms and look better). Throws
// std::invalid_argument if S's cell size is not the map's resolution or a parameter is out of range.
ApsResult aps_match(const IntensityGrid& S, IntensityMap& map, const ApsParams& params = {});

// The steps of aps_match that stand on their own. In its order: check the inputs; the search window;
// where S is usable (S_n > n_e); the map resampled under S and the window; per offset, the sum of
// squared z-scores of Eq. 14; Eq. 14 in logs; the peak's place and the moments (Eq. 15-16); the
// position (Eq. 17-18).

// The offsets APS scores: -nx..nx steps along x (longitudinal), -ny..ny along y (lateral), each step
// `step_cells` cells of S, which are the map's cells.
struct ApsSearchWindow {
  int nx = 0, ny = 0;
  int step_cells = 1;
  double step_m = 0;

  int offsets_x() const { return 2 * nx + 1; }
  int offsets_y() const { return 2 * ny + 1; }
  // How far the offsets reach beyond S on each side, in cells.
  int margin_x() const { return nx * step_cells; }
  int margin_y() const { return ny * step_cells; }
  // Offset (i, j), i in [0, offsets_x()) and j in [0, offsets_y()), in the vehicle frame (m).
  Eigen::Vector2d offset(int i, int j) const { return {(i - nx) * step_m, (j - ny) * step_m}; }
};

// The window of params' ranges (whole steps: a range that is a multiple of the step keeps its last
// one) for cells of cell_m. Throws std::invalid_argument unless step_m is a positive whole number of
// cells and the ranges are finite and non-negative.
ApsSearchWindow aps_search_window(const ApsParams& params, double cell_m);

// Eq. 14 in logs, offset by offset: log P = -alpha / 2 * (the offset's sum of squared z-scores
// (m_r - s_r)^2 / (m_sigma + s_sigma)^2). Up to a constant, which the moments do not need.
std::vector<double> aps_log_probabilities(const std::vector<float>& z_score_sums, double alpha);

// The margin along the road: over each longitudinal offset's best lateral one, Eq. 14's log P plus the
// log of a Gaussian prior of prior_sigma_m along the road centred on the window (the posterior, up to a
// constant), of the best minus that of the best local peak farther than separation_m from it along the
// road (a border offset counts as a peak if it is above its one neighbour: the rising flank of a peak
// beyond the window). +inf without one. log_p: row-major, offsets_x() per row.
double aps_along_margin(const std::vector<double>& log_p, const ApsSearchWindow& window, double separation_m,
                        double prior_sigma_m = std::numeric_limits<double>::infinity());

// Whether the most probable offset lies on the window's border (along an axis with more than one
// offset). log_p: row-major, offsets_x() per row.
bool aps_peak_on_edge(const std::vector<double>& log_p, const ApsSearchWindow& window);

// Eq. 15-16: the centre of mass of P over the offsets, and P's covariance plus the variance of a
// uniform spread over one step (the estimate is only known to a step), vehicle frame.
struct OffsetMoments {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};
OffsetMoments aps_offset_moments(const std::vector<double>& log_p, const ApsSearchWindow& window);

// Eq. 14's rules for one cell, for searches that score offsets as aps_match does (wide_search.hpp):
// whether a cell of S is in the effective area (S_n > n_e), and a cell's standard deviation with the
// min_sigma floor.
bool aps_cell_usable(const IntensityCell& s, const ApsParams& params);
double aps_cell_sigma(const IntensityCell& cell, double min_sigma);

}  // namespace lidarloop
