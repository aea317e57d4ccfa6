// Curb matching over a grid of hypotheses. See curb_hypotheses.hpp.
#include "localizer/curb_hypotheses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lidarloop {
namespace {

// Ranges over steps are rounded with this tolerance, so a range that is a multiple of its step keeps
// its last step.
constexpr double kStepTolerance = 1e-9;

void check_params(const CurbHypothesesParams& p) {
  auto finite_non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!finite_non_negative(p.longitudinal_range_m) || !finite_non_negative(p.lateral_range_m) ||
      !finite_non_negative(p.yaw_range_rad))
    throw std::invalid_argument("curb_hypotheses: search ranges must be finite and non-negative");
  if (!positive(p.longitudinal_step_m) || !positive(p.lateral_step_m) || !positive(p.yaw_step_rad))
    throw std::invalid_argument("curb_hypotheses: steps must be positive numbers");
  if (!positive(p.inlier_distance_m) || !finite_non_negative(p.cluster_radius_m) ||
      !finite_non_negative(p.cluster_yaw_rad) || !finite_non_negative(p.ambiguity_score))
    throw std::invalid_argument("curb_hypotheses: inlier distance, cluster sizes and ambiguity must be >= 0");
  if (p.max_starts < 1 || p.max_icp_curbs < 1)
    throw std::invalid_argument("curb_hypotheses: max_starts and max_icp_curbs must be >= 1");
}

// -n..n steps of `step` within +-range.
std::vector<double> steps(double range, double step) {
  const int n = static_cast<int>(std::floor(range / step + kStepTolerance));
  std::vector<double> v;
  for (int k = -n; k <= n; ++k) v.push_back(k * step);
  return v;
}

// How well the features moved by `correction` lie on the map's curbs.
CurbHypothesis scored(const std::vector<Eigen::Vector2d>& features, const MapIndex& map, const Pose2d& prior,
                      const Pose2d& correction, double inlier_distance) {
  CurbHypothesis h;
  h.correction = correction;
  h.pose = correction.compose(prior);
  size_t inliers = 0;
  double residuals = 0, kernel = 0;
  const PoseApplier corrected(correction);
  for (const Eigen::Vector2d& f : features) {
    const double d = map.nearest_within(corrected(f), inlier_distance).second;
    if (!(d <= inlier_distance)) continue;
    ++inliers;
    residuals += d;
    kernel += 1.0 - (d / inlier_distance) * (d / inlier_distance);
  }
  const double n = double(features.size());
  h.inlier_ratio = double(inliers) / n;
  h.mean_residual_m = inliers ? residuals / double(inliers) : 0.0;
  h.score = kernel / n;
  return h;
}

// The ICP starting corrections: the grid over the window in the prior's vehicle frame, as offsets
// (the corrections of a step's prior are made from them), thinned evenly to at most max_starts.
std::vector<Pose2d> start_offsets(const CurbHypothesesParams& p) {
  std::vector<Pose2d> grid;
  for (double yaw : steps(p.yaw_range_rad, p.yaw_step_rad))
    for (double y : steps(p.lateral_range_m, p.lateral_step_m))
      for (double x : steps(p.longitudinal_range_m, p.longitudinal_step_m)) grid.push_back({x, y, yaw});
  if (grid.size() <= size_t(p.max_starts)) return grid;
  std::vector<Pose2d> thinned;
  for (size_t k = 0; k < size_t(p.max_starts); ++k) thinned.push_back(grid[k * grid.size() / size_t(p.max_starts)]);
  return thinned;
}

// ICP's cost is per curb: a subset spread evenly over the features keeps it bounded; every curb scores
// the places.
std::vector<Eigen::Vector2d> icp_subset(const std::vector<Eigen::Vector2d>& features, int max_curbs) {
  std::vector<Eigen::Vector2d> subset;
  const size_t n = std::min(features.size(), size_t(max_curbs));
  for (size_t k = 0; k < n; ++k) subset.push_back(features[k * features.size() / n]);
  return subset;
}

// Every converged correction scored on the features at `prior`, clustered into places, and the
// ambiguity of the best.
CurbHypothesesResult places(const std::vector<Pose2d>& converged, const std::vector<Eigen::Vector2d>& features_world,
                            const MapIndex& map, const Pose2d& prior, const CurbHypothesesParams& params) {
  CurbHypothesesResult result;
  std::vector<CurbHypothesis> solutions;
  for (const Pose2d& t : converged) {
    // A solution outside the window (a step's reach beyond it) is another place than the one searched
    // for: at a junction, the cross street turned by 90 degrees.
    const Pose2d d = relative(prior, t.compose(prior));
    if (std::fabs(d.x) > params.longitudinal_range_m + params.longitudinal_step_m ||
        std::fabs(d.y) > params.lateral_range_m + params.lateral_step_m ||
        std::fabs(d.yaw) > params.yaw_range_rad + params.yaw_step_rad)
      continue;
    solutions.push_back(scored(features_world, map, prior, t, params.inlier_distance_m));
  }
  // Greedy clustering, best first: a solution joins the first place within the cluster's size.
  std::stable_sort(solutions.begin(), solutions.end(),
                   [](const CurbHypothesis& a, const CurbHypothesis& b) { return a.score > b.score; });
  for (const CurbHypothesis& s : solutions) {
    if (!(s.score > 0)) continue;  // explains no curb: not a place
    const auto near = std::find_if(result.places.begin(), result.places.end(), [&](const CurbHypothesis& c) {
      return std::hypot(c.pose.x - s.pose.x, c.pose.y - s.pose.y) <= params.cluster_radius_m &&
             std::fabs(wrap_angle(c.pose.yaw - s.pose.yaw)) <= params.cluster_yaw_rad;
    });
    if (near != result.places.end()) {
      ++near->starts;
      continue;
    }
    result.places.push_back(s);
    result.places.back().starts = 1;
  }
  if (result.places.empty()) return result;
  result.ok = true;
  result.best = result.places.front();
  if (result.places.size() > 1) result.score_margin = result.best.score - result.places[1].score;
  for (const CurbHypothesis& c : result.places) {
    if (c.score < result.best.score - params.ambiguity_score) break;  // sorted: the rest fit worse
    const Pose2d d = relative(result.best.pose, c.pose);
    result.spread = result.spread.cwiseMax(Eigen::Vector3d(d.x, d.y, d.yaw).cwiseAbs());
  }
  result.ambiguous_longitudinal = result.spread.x() > params.cluster_radius_m;
  result.ambiguous_lateral = result.spread.y() > params.cluster_radius_m;
  result.ambiguous_yaw = result.spread.z() > params.cluster_yaw_rad;
  return result;
}

}  // namespace

CurbHypothesisSearch::CurbHypothesisSearch(const CurbHypothesesParams& params) : params_(params) {
  check_params(params_);
  if (params_.max_icp_runs_per_step < 1)
    throw std::invalid_argument("curb_hypotheses: max_icp_runs_per_step must be >= 1");
}

void CurbHypothesisSearch::restart() { *this = CurbHypothesisSearch(params_); }

void CurbHypothesisSearch::step(const std::vector<Eigen::Vector2d>& features_world, const MapIndex& map,
                                const Pose2d& prior) {
  if (done_ || features_world.size() < size_t(std::max(params_.min_curbs, 1)) || map.empty()) return;
  const std::vector<Pose2d> offsets = start_offsets(params_);
  const std::vector<Eigen::Vector2d> subset = icp_subset(features_world, params_.max_icp_curbs);
  for (int run = 0; run < params_.max_icp_runs_per_step && next_start_ < offsets.size(); ++run) {
    const Pose2d start = prior.compose(offsets[next_start_++]).compose(prior.inverse());
    converged_.push_back(icp(map, subset, start, params_.icp).t);
    ++icp_runs_;
  }
  if (next_start_ < offsets.size()) return;
  done_ = true;
  result_ = places(converged_, features_world, map, prior, params_);
  result_.icp_runs = icp_runs_;
}

CurbHypothesesResult curb_hypotheses(const std::vector<Eigen::Vector2d>& features_world, const MapIndex& map,
                                     const Pose2d& prior, const CurbHypothesesParams& params) {
  CurbHypothesesParams unlimited = params;
  unlimited.max_icp_runs_per_step = std::numeric_limits<int>::max();
  CurbHypothesisSearch search(unlimited);
  search.step(features_world, map, prior);
  return search.result();
}

}  // namespace lidarloop
