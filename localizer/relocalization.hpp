#pragma once
// Relocalization (beyond the paper): while the localizer is lost, the wide searches of intensity
// (wide_search.hpp: APS over x, y and yaw, coarse to fine) and curbs (curb_hypotheses.hpp: ICP from a
// grid of starts) run over the window the filter's doubt spans, a share per scan, and decide where the
// car is. Each scan runs one of the two (taking turns when both have data), so a scan stays within the
// localizer's budget; a search over +-6 m and +-4 deg takes about five shares.
//
// What a finished search may claim:
//   - all of x, y and yaw when its best place beats every other distinct place clearly (APS: by
//     min_aps_margin in Eq. 14's log probability with the hypotheses' prior; curbs: no other place fits
//     as well on any axis);
//   - only the lateral position and the heading when the other places that fit as well lie along the
//     road from the best (dashed lines repeat every few metres, straight curbs say nothing along it),
//     unless for APS the prior (the GPS) alone rules the other place out;
//     The localizer stays lost then, and searches again from the corrected pose.
// Anything else is refused, and the search starts again on the next scans. A whole place is taken only
// when two searches in a row find it (the same place, carried with the car by odometry, within
// confirm_distance_m and confirm_yaw_deg): a wrong place that one scan's paint favours (worn or
// repainted lines) seldom wins twice.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"
#include "localizer/curb_hypotheses.hpp"
#include "localizer/map_index.hpp"
#include "localizer/wide_search.hpp"

namespace lidarloop {

struct RelocalizationParams {
  // The search window is this many sigmas of the filter's spread on each axis of the car...
  double window_sigmas = 3.0;
  // On becoming lost the filter's spread grows so that the farthest observation it refused (the truth
  // may be there) lies this many sigmas out: the window then reaches half as far again beyond it.
  double lost_offset_sigmas = 2.0;
  double min_range_m = 2.0;  // half extent on each axis, at least
  double max_longitudinal_m = 8.0, max_lateral_m = 6.0;
  // The heading doubt of a lost filter (1 sigma, deg): the paper's receiver's heading error (1.5-2 deg),
  // which is all a cold start or a kidnapped filter can vouch for; and the most searched.
  double lost_yaw_sigma_deg = 1.5;
  double max_yaw_deg = 6.0;
  double min_curb_score = 0.5;  // curb places explaining less (curb_hypotheses.hpp's score) are refused
  // APS's best must beat the best distinct other place by this much log probability (Eq. 14 with the
  // prior). Stripes repeating every 3 m measured ~40 (ambiguous), paint across the road 370-1200.
  double min_aps_margin = 100.0;
  // A place must lie within the 99.9 % region of one of the hypotheses: half chi^2 with 3 dof.
  double max_prior_term = 0.5 * 16.27;
  // Along the road, the best of repeating paint is taken when the prior alone makes the other place this
  // much less likely (half the squared sigmas: 4.5 is 3 sigma farther out).
  double min_prior_gap = 4.5;
  // The places that fit as well lie along the road when they are within this of the best across it
  // (m) and in heading (deg): the lateral position is then fixed, and the heading too if APS's own
  // spread in heading is within the same.
  double along_road_lateral_m = 0.4, along_road_yaw_deg = 0.5;
  double confirm_distance_m = 0.5, confirm_yaw_deg = 0.5;
  WideApsParams aps;  // its ranges are set per search
  CurbHypothesesParams curbs;
};

// Where the car may be by what the localizer knew before the search: the filter's pose from before it
// was lost (the GPS may be what jumped) and the GPS's fix (the filter may be what was kidnapped), each
// with its sigmas (longitudinal m, lateral m, yaw rad in its own vehicle frame).
struct Hypothesis {
  Pose2d centre;
  Eigen::Vector3d sigmas = Eigen::Vector3d::Ones();
};

struct Relocation {
  Pose2d pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // x, y, psi; local frame
  bool longitudinal = true;                                  // false: not the position along the road
  bool heading = true;  // false: not the heading either (only the lateral position)
};

class Relocalizer {
 public:
  explicit Relocalizer(const RelocalizationParams& params = {}) : p_(params) {}

  // A new search around the prior over half ranges (longitudinal m, lateral m, yaw rad; vehicle frame).
  // The places found are weighed by the likelier of the hypotheses (Eq. 14 times a Gaussian prior).
  // `odometry`: the dead-reckoning pose now, by which the hypotheses move with the car from share to share.
  void start(const Eigen::Vector3d& half_ranges, const std::vector<Hypothesis>& hypotheses, const Pose2d& odometry);
  bool active() const { return active_; }
  // A search ends; a place found once and waiting to be found again stays (stop) or is dropped (finish:
  // the localizer is found).
  void stop() { active_ = false; }
  void finish() {
    active_ = false;
    pending_.reset();
  }
  // One share. `S` (at `prior`, or null), the curb features placed at `prior` (world frame) with the
  // map's curbs around it (or empty). A relocation when a search has finished and found one.
  std::optional<Relocation> step(IntensityGrid* S, IntensityMap& intensity, const std::vector<Eigen::Vector2d>& curbs,
                                 const MapIndex& curb_map, const Pose2d& prior, const Pose2d& odometry);

 private:
  std::optional<Relocation> verdict(const WideApsResult& r, const Pose2d& prior) const;
  std::optional<Relocation> verdict(const CurbHypothesesResult& r, const Pose2d& prior) const;
  // A whole place found twice in a row passes; the first time it is kept (moved with the car by
  // odometry), also across searches restarted meanwhile (the narrow matchers or a search that placed the
  // car only across the road moved the filter).
  std::optional<Relocation> confirmed(const std::optional<Relocation>& found);
  std::optional<Pose2d> pending_;

  RelocalizationParams p_;
  bool active_ = false;
  bool curbs_turn_ = false;
  std::vector<Hypothesis> hypotheses_;
  // The hypotheses and the pending place moved with the car to where odometry now has it.
  void carry(const Pose2d& odometry);
  Pose2d odometry_;  // when they were last moved
  // Minus the log of the likelier hypothesis's Gaussian at `pose` (up to a constant).
  double prior_term(const Pose2d& pose) const;
  WideApsSearch aps_;
  CurbHypothesisSearch curbs_;
};

// Lateral position and heading of `found`, longitudinal position of `prior` (found's vehicle frame).
Pose2d lateral_and_heading(const Pose2d& found, const Pose2d& prior);

}  // namespace lidarloop
