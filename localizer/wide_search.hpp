#pragma once
// Relocalization by intensity: APS (the paper's Eq. 14) over x, y AND yaw in a window of several metres
// and degrees around a prior, for a cold start or a lost filter. aps_match searches +-3 m x +-1 m at the
// prior's yaw, which cannot correct a GPS fix 2-5 m and a few degrees off.
//
// Why coarse to fine: scoring every 0.2 m offset of a +-6 m window at every 0.25 deg of +-4 deg is
// 61 x 61 x 33 poses times thousands of cells, about a second. The paint that decides the match is
// still visible when S and the map are merged into 0.8 m cells (Eq. 8's statistics merged exactly, so a
// cell half paint half asphalt has the mean and the spread of both), where the same window is 15 x 15
// offsets at 1 deg steps on a sixteenth of the cells (S's cells turned with each yaw and merged anew).
// The coarse level keeps the best few distinct peaks; each is refined at the map's resolution in a
// window of +-3 cells and then in finer yaw steps, where the scores are aps_match's own (the same alpha,
// min_sigma, n_e and cells-under-map rule; at yaw zero the same sums).
//
// Budget: the localizer's scan takes 5-10 ms of a p50 8 ms / p99 20 ms budget, so the search is made of
// units (one yaw slice of the coarse grid, one candidate's refinement) and WideApsSearch::step runs as
// many as a budget of z-score terms allows, resuming on the next scan: 3-6 ms of CPU a step, five or six
// steps (the one that ends the coarse phase stops there; bench_wide_search; the whole search in one call
// is ~20 ms). Candidates are kept as
// corrections of the prior (rigid transforms of the local frame: pose = correction * prior), which stay
// valid while the prior moves with odometry.
//
// Distinctiveness: periodic paint (dashed lines, zebra stripes) or a lone line along the road gives
// peaks of nearly equal probability. The result says by how much the best beats the best candidate
// farther than distinct_separation_m from it, and where that one is; the caller must refuse a small
// margin. The other peaks of periodic paint are translations of the best, so every candidate is also
// tried at the leading one's yaw: a coarse yaw a step off must not hide an alias. At the end every
// refined candidate is scored once more on the last step's S and on the cells all of them see (the
// verdict), so that candidates refined on different scans compare like with like.
#include <cstdint>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"
#include "localizer/aps_matcher.hpp"
#include "localizer/intensity_map.hpp"

namespace lidarloop {

struct WideApsParams {
  // Half ranges of the search around the prior, in its vehicle frame: a low-cost GPS fix's few metres
  // (the cold start is 2-5 m off) and heading degrees.
  double longitudinal_range_m = 6.0;
  double lateral_range_m = 6.0;
  double yaw_range_rad = 4.0 * std::numbers::pi / 180.0;
  // Eq. 14's alpha, min_sigma, n_e and min_cells, as aps_match takes them (its window is not used).
  ApsParams aps;
  // Fine cells (the map's) per coarse cell side: 4 x 0.2 m = 0.8 m, still finer than a lane line's
  // dashes and gaps (3 m and more), so the coarse peak is within one coarse cell of the fine one.
  int coarse_factor = 4;
  // Yaw step of the coarse level: at S's corner (28 m from the car) 1 deg moves a cell 0.5 m, within a
  // coarse cell.
  double coarse_yaw_step_rad = 1.0 * std::numbers::pi / 180.0;
  // Yaw step of the refinement, which covers +-half a coarse step: 0.25 deg moves S's corner 0.12 m,
  // about half a fine cell, below which the map cannot tell yaws apart.
  double fine_yaw_step_rad = 0.25 * std::numbers::pi / 180.0;
  // Refinement window, +- this many fine cells around a coarse candidate (re-centred once if the peak
  // is on its edge): 0.6 m, more than the half coarse cell within which the fine peak lies when the
  // coarse one is right.
  int refine_radius_cells = 3;
  // Coarse peaks refined (top k, pairwise farther apart than distinct_separation_m).
  int candidates = 4;
  // Two peaks closer than this are one (m). Above the refinement's reach (0.6 m) and below the period
  // of the paint that repeats soonest on a road (a crosswalk's ~1 m is finer than the coarse level can
  // see; dashes repeat every 3-12 m), so a period of paint shows as a second candidate.
  double distinct_separation_m = 1.5;
  // A search made of fewer usable coarse cells than this says nothing (ok = false); aps.min_cells
  // applies to the fine level.
  int min_coarse_cells = 10;
  // Work per WideApsSearch::step, in z-score terms of Eq. 14 (one cell of S at one pose). The coarse
  // phase is ~1.5 M terms and each refinement ~2.3 M for Table I's S over a 12 m wide road, so the
  // default runs one of them per step: 3-6 ms on one core with the map reads (bench_wide_search), five
  // or six steps in all, the last with the verdict. A unit is never split: a step does at least one.
  int64_t max_terms_per_step = 2'500'000;
};

struct WideApsResult {
  bool ok = false;  // a finished search with enough cells at both levels
  // The most probable pose (local frame): Eq. 15-16's centre of mass over +-refine_radius_cells around
  // the best candidate's peak at its best yaw, and the centre of mass of its yaw distribution.
  Pose2d pose;
  Pose2d correction;  // pose = correction.compose(prior): a rigid transform of the local frame
  // (x, y, yaw), local frame: x, y from Eq. 15-16's moments at the best yaw, yaw from the distribution
  // over the refinement's yaws (each the sum of P over +-1 cell around the peak); each plus a step's
  // quantisation. Over a window that small a ridge (a lone line along the road) is cut short: the
  // margin, not this, says whether the search is ambiguous.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  // The verdict's cells: those of the last step's S with map data under them at every refined
  // candidate's pose (the cells-under-map rule across the candidates).
  int cells_used = 0;
  // Eq. 14 in logs (up to a constant) at the best pose, on those cells.
  double log_p = 0;
  // Distinctiveness: log P of the best minus that of the best refined candidate farther than
  // distinct_separation_m from it, both scored on the last step's S and the same cells (the verdict);
  // +inf when there is none. Its noise grows with the square root of the cells: in the tests (~8000
  // cells, alpha 0.5) stripes every 3 m gave ~40, unique paint ~5000; on the campus map, S over a
  // stretch of road with only its centre line gave below 1, with paint across the road in view 370-1200.
  double margin = 0;
  Pose2d runner_up;  // that candidate's pose (local frame), when margin is finite
  // Every refined candidate: its pose (local frame) and Eq. 14's log P on the best's count of cells, as
  // log_p is (so a caller can weigh them with a prior of its own).
  struct Place {
    Pose2d pose;
    double log_p = 0;
  };
  std::vector<Place> places;
  // The best lies within a coarse cell of the search range's border: the truth may be outside.
  bool peak_on_edge = false;
  int64_t offsets_evaluated = 0;  // poses (x, y, yaw) scored at both levels
  int64_t terms_evaluated = 0;    // z-score terms of Eq. 14 summed, the cost
};

// A place a search found, as a correction of the prior it was found at, with its peak's Eq. 14 log P
// per cell of S (comparable across scans, whose S differ) and, once refined, its spread.
struct WideApsCandidate {
  Pose2d correction;
  double log_p_per_cell = 0;
  int cells = 0;
  Eigen::Matrix2d offset_covariance = Eigen::Matrix2d::Zero();  // vehicle frame, Eq. 15-16
  double yaw_variance = 0;
};

// The search in one go: WideApsSearch with an unlimited budget, stepped on the same S until done. S.pose is the prior
// and the window's centre. Throws std::invalid_argument if S's cell is not the map's or a parameter is out of range.
WideApsResult wide_aps_search(const IntensityGrid& S, IntensityMap& map, const WideApsParams& params = {});

// The same search spread over scans. Each step takes the newest S (S.pose its prior) and runs units of
// the search until max_terms_per_step would be exceeded; what it found is kept as corrections of the
// prior it was found at. Coarse scores of different scans are compared per cell of S.
class WideApsSearch {
 public:
  explicit WideApsSearch(const WideApsParams& params = {});
  // One share of the search; nothing once done().
  void step(const IntensityGrid& S, IntensityMap& map);
  bool done() const { return phase_ == Phase::done; }
  // The result at the last step's prior; ok = false until done().
  const WideApsResult& result() const { return result_; }
  // Forget everything and start again.
  void restart();

 private:
  enum class Phase { coarse, fine, done };
  WideApsParams params_;
  Phase phase_ = Phase::coarse;
  int next_unit_ = 0;                      // yaw slice (coarse) or candidate (fine)
  std::vector<WideApsCandidate> pool_;     // coarse local maxima so far
  std::vector<WideApsCandidate> refined_;  // the distinct best of the pool, refined in the fine phase
  WideApsResult result_;
  int64_t offsets_ = 0, terms_ = 0;
};

}  // namespace lidarloop
