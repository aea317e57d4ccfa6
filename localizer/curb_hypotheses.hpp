#pragma once
// Relocalization by curbs: ICP (Eq. 9) from a grid of starting corrections over a window of several
// metres and degrees around the prior, for a cold start or a lost filter. One ICP from the prior only
// finds the nearest minimum, and with a prior 2-5 m off that is often a curb matched to the wrong one.
// The converged solutions are clustered, each place is scored by how many curbs it explains and how
// closely, and the result says per axis whether another place fits nearly as well: on a straight road
// two straight curbs fix the lateral position and the heading but nothing along the road, so the
// caller can take only the lateral and yaw part.
//
// Cost: one ICP run is up to 20 iterations of a nearest-neighbour query per curb within a 2 m gate
// (MapIndex's buckets), ~0.1-0.2 ms on 50 curbs; the default grid is 7 x 7 x 3 = 147 starts, 15-25 ms
// in all, too much for one scan beside the localizer's 5-10 ms. CurbHypothesisSearch spreads the
// starts over scans, max_icp_runs_per_step at a time, keeping what converged as corrections of the
// prior (valid while the prior moves with odometry) and scoring every place on the last scan's curbs
// (bench_wide_search measures a step and the whole search).
#include <cstdint>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"
#include "localizer/map_index.hpp"
#include "localizer/probabilistic_icp.hpp"

namespace lidarloop {

struct CurbHypothesesParams {
  // Half ranges of the starts around the prior, in its vehicle frame (a low-cost GPS fix's error).
  double longitudinal_range_m = 6.0;
  double lateral_range_m = 6.0;
  double yaw_range_rad = 4.0 * std::numbers::pi / 180.0;
  // Steps of the grid of starts. ICP converges from about half its correspondence gate, so a step of
  // twice that leaves no gap: every place in the window is within reach of a start.
  double longitudinal_step_m = 2.0;
  double lateral_step_m = 2.0;
  double yaw_step_rad = 4.0 * std::numbers::pi / 180.0;
  // ICP from each start: a correspondence gate of 2 m reaches a curb a step away; the rest as in
  // IcpParams. Loose convergence: the clusters are 0.5 m wide, the caller refines the winner.
  IcpParams icp{20, 1e-3, 2.0};
  // A curb within this of the map after the match is explained by it (m): the detector's and the
  // map's errors together (a few centimetres each) and the accumulation's drift.
  double inlier_distance_m = 0.3;
  // Solutions closer than this (m, rad) are one place.
  double cluster_radius_m = 0.5;
  double cluster_yaw_rad = 1.0 * std::numbers::pi / 180.0;
  // A place whose score is within this of the best's fits as well (the scores are fractions of the
  // curbs: 0.05 is one curb in twenty).
  double ambiguity_score = 0.05;
  // At most this many ICP runs (the grid is thinned evenly beyond it).
  int max_starts = 160;
  // ICP runs per CurbHypothesisSearch::step: ~4 ms (bench_wide_search), five steps for the grid.
  int max_icp_runs_per_step = 32;
  // ICP runs on at most this many curbs (spread evenly over the features); all of them score the
  // places. 50 curbs along 40 m of two curbs are one every 1.6 m, enough to pin a transform.
  int max_icp_curbs = 50;
  int min_curbs = 10;  // fewer curb features: no search (ok = false)
};

struct CurbHypothesis {
  Pose2d correction;           // pose = correction.compose(prior): ICP's transform of the world-frame features
  Pose2d pose;                 // local frame
  double inlier_ratio = 0;     // curbs within inlier_distance_m of the map
  double mean_residual_m = 0;  // over those
  // inlier_ratio discounted by the inliers' mean squared residual over inlier_distance_m^2: the mean
  // over all curbs of max(0, 1 - (d / inlier_distance_m)^2). 1 when every curb is on the map.
  double score = 0;
  int starts = 0;  // ICP runs that ended here
};

struct CurbHypothesesResult {
  bool ok = false;  // enough curbs and at least one place explaining some of them
  CurbHypothesis best;
  std::vector<CurbHypothesis> places;  // every cluster, best first
  // Distinctiveness: best.score minus the best score of another place; 1 (a full score) when there is
  // none.
  double score_margin = 1;
  // How far the places that fit as well as the best (within ambiguity_score) reach from it on each axis
  // of the best's vehicle frame: (longitudinal m, lateral m, yaw rad). The best's frame, not the
  // prior's: along a straight road the places line up with the road, and in a frame turned by the
  // prior's few degrees of error their spread along it would show as a lateral one.
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
  // Whether that reach exceeds the cluster size: the curbs do not fix this axis, the caller must not
  // use it. A straight road: longitudinal only.
  bool ambiguous_longitudinal = false, ambiguous_lateral = false, ambiguous_yaw = false;
  int icp_runs = 0;
};

// The search in one go (CurbHypothesisSearch without a limit per step). features_world: the curb
// features placed at `prior` (world = local frame); map: the map's curbs around the prior.
// Deterministic. Throws std::invalid_argument for a parameter out of range.
CurbHypothesesResult curb_hypotheses(const std::vector<Eigen::Vector2d>& features_world, const MapIndex& map,
                                     const Pose2d& prior, const CurbHypothesesParams& params = {});

// The same search spread over scans: each step takes the newest features, placed at the newest prior,
// and runs the next max_icp_runs_per_step starts of the grid (the grid is relative to each step's
// prior). Once all have run, every place found is scored on the last step's features.
class CurbHypothesisSearch {
 public:
  explicit CurbHypothesisSearch(const CurbHypothesesParams& params = {});
  // One share of the search; nothing once done(). Fewer than min_curbs features: the step does nothing.
  void step(const std::vector<Eigen::Vector2d>& features_world, const MapIndex& map, const Pose2d& prior);
  bool done() const { return done_; }
  // The result at the last step's prior; ok = false until done().
  const CurbHypothesesResult& result() const { return result_; }
  void restart();

 private:
  CurbHypothesesParams params_;
  size_t next_start_ = 0;
  std::vector<Pose2d> converged_;  // ICP's corrections of the prior, one per start run
  int icp_runs_ = 0;
  bool done_ = false;
  CurbHypothesesResult result_;
};

}  // namespace lidarloop
