#include "loop/scorer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

#include "common/pose2d.hpp"
#include "common/units.hpp"

namespace lidarloop {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMedianPercent = 50.0;
constexpr double kTailPercent = 99.0;
// m along the route either side of the previous sample's projection: far more than the car moves
// between two truth samples, far less than the way round to another stretch of road near this one.
constexpr double kLaneSearch = 30.0;

// "lateral RMSE 0.310 m > 0.200 m". Millimetre (millidegree) digits so a value just over its
// threshold never prints as equal to it.
std::string failure(const char* what, double value, double threshold, const char* unit) {
  char text[128];
  std::snprintf(text, sizeof text, "%s %.3f %s > %.3f %s", what, value, unit, threshold, unit);
  return text;
}

void check(Metrics& m, const char* what, double value, const std::optional<double>& threshold, const char* unit) {
  // Written as !(value <= threshold) so that NaN (a diverged estimate) fails instead of passing.
  if (threshold && !(value <= *threshold)) m.failures.push_back(failure(what, value, *threshold, unit));
}

// A lower bound, e.g. "coverage 0.812 < 0.900".
void check_at_least(Metrics& m, const char* what, double value, const std::optional<double>& threshold) {
  if (!threshold || value >= *threshold) return;
  char text[128];
  std::snprintf(text, sizeof text, "%s %.3f < %.3f", what, value, *threshold);
  m.failures.push_back(text);
}

}  // namespace

FrameError frame_error(const Pose2d& truth, const Pose2d& estimate) {
  const double dx = estimate.x - truth.x, dy = estimate.y - truth.y;
  const double c = std::cos(truth.yaw), s = std::sin(truth.yaw);
  FrameError e;
  e.longitudinal_m = c * dx + s * dy;
  e.lateral_m = -s * dx + c * dy;
  e.heading_rad = wrap_angle(estimate.yaw - truth.yaw);
  e.position_m = std::hypot(dx, dy);
  e.truth = truth;
  e.estimate = estimate;
  return e;
}

Pose2d truth_at(const std::vector<TruthPose>& truth, int64_t t_ns) {
  if (truth.empty()) throw std::out_of_range("truth_at: no ground truth");
  if (t_ns < truth.front().stamp_ns || t_ns > truth.back().stamp_ns)
    throw std::out_of_range("truth_at: t = " + std::to_string(t_ns) + " ns is outside the ground truth's range [" +
                            std::to_string(truth.front().stamp_ns) + ", " + std::to_string(truth.back().stamp_ns) +
                            "] ns");
  // The first sample after t; the one before it is at or before t.
  const auto after =
      std::upper_bound(truth.begin(), truth.end(), t_ns, [](int64_t t, const TruthPose& p) { return t < p.stamp_ns; });
  if (after == truth.end()) return truth.back().pose;  // t is the last stamp
  const TruthPose& a = *(after - 1);
  const TruthPose& b = *after;
  const double f = double(t_ns - a.stamp_ns) / double(b.stamp_ns - a.stamp_ns);
  return {a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
          wrap_angle(a.pose.yaw + f * wrap_angle(b.pose.yaw - a.pose.yaw))};
}

Coverage estimate_coverage(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates,
                           int64_t scan_period_ns) {
  Coverage c;
  if (truth.empty() || truth.back().stamp_ns <= truth.front().stamp_ns) return c;
  const int64_t begin = truth.front().stamp_ns, end = truth.back().stamp_ns, half = scan_period_ns / 2;
  std::vector<int64_t> stamps;
  stamps.reserve(estimates.size());
  for (const EstimateRecord& e : estimates) stamps.push_back(e.stamp_ns);
  std::sort(stamps.begin(), stamps.end());
  // Integer nanoseconds throughout: the same estimates give the same figures on every path.
  int64_t covered = 0, gap = 0, reached = begin;  // the span is covered from `begin` to `reached`
  for (int64_t t : stamps) {
    const int64_t from = std::clamp(t - half, begin, end), to = std::clamp(t + half, begin, end);
    if (to <= reached) continue;
    gap = std::max(gap, from - reached);
    covered += to - std::max(from, reached);
    reached = to;
  }
  gap = std::max(gap, end - reached);
  c.fraction = double(covered) / double(end - begin);
  c.largest_gap_s = double(gap) / double(kNsPerS);
  return c;
}

double rmse(const std::vector<double>& values) {
  if (values.empty()) return kNaN;
  double sum = 0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / double(values.size()));
}

double percentile_nearest_rank(std::vector<double> values, double percent) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(percent / 100.0 * double(values.size()));
  const size_t index = size_t(std::clamp(rank, 1.0, double(values.size()))) - 1;
  return values[index];
}

std::vector<double> lane_offsets(const std::vector<TruthPose>& truth, const Path& route) {
  if (route.points.size() < 2) throw std::invalid_argument("lane_offsets: the route has fewer than two points");
  std::vector<double> offsets;
  offsets.reserve(truth.size());
  double s = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Vector2d p(truth[i].pose.x, truth[i].pose.y);
    // The window is not clamped to [0, length]: on a closed route Path::project takes an unwrapped
    // window across the seam and answers unwrapped, so s keeps counting laps; an open route clamps it.
    s = i == 0 ? route.project(p) : route.project(p, s - kLaneSearch, s + kLaneSearch);
    const Pose2d on = route.pose_at(s);
    offsets.push_back(-std::sin(on.yaw) * (p.x() - on.x) + std::cos(on.yaw) * (p.y() - on.y));
  }
  return offsets;
}

CurbOcclusion curb_occlusion(const std::vector<CurbVisibility>& scans) {
  CurbOcclusion o;
  int64_t hidden = 0, in_sight = 0;  // in sight: of the static world, so hidden or visible
  for (const CurbVisibility& v : scans) {
    const int scan_in_sight = v.hidden + v.visible;
    if (scan_in_sight == 0) continue;
    hidden += v.hidden;
    in_sight += scan_in_sight;
    const double fraction = double(v.hidden) / double(scan_in_sight);
    if (!(fraction <= o.hidden_fraction_max)) o.hidden_fraction_max = fraction;  // NaN at first
  }
  if (in_sight > 0) o.hidden_fraction = double(hidden) / double(in_sight);
  return o;
}

ScoredRun score(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates, const Path& route,
                const PassThresholds& thresholds, const std::string& method, const std::string& scenario,
                const std::vector<CurbVisibility>& curb_visibility, int64_t scan_period_ns) {
  if (!std::is_sorted(truth.begin(), truth.end(),
                      [](const TruthPose& a, const TruthPose& b) { return a.stamp_ns < b.stamp_ns; }))
    throw std::invalid_argument("score: ground truth is not sorted by stamp");
  ScoredRun run;
  Metrics& m = run.metrics;
  m.method = method;
  m.scenario = scenario;
  m.thresholds = thresholds;

  std::vector<double> lateral, longitudinal, heading_deg, position, latency;
  for (size_t i = 0; i < estimates.size(); ++i) {
    const EstimateRecord& est = estimates[i];
    if (std::isfinite(est.latency_ms)) latency.push_back(est.latency_ms);
    if (truth.empty() || est.stamp_ns < truth.front().stamp_ns || est.stamp_ns > truth.back().stamp_ns) {
      ++m.unscored_frames;
      continue;
    }
    if (double(est.stamp_ns - estimates.front().stamp_ns) < thresholds.settle_s * double(kNsPerS)) {
      ++m.settling_frames;
      continue;
    }
    FrameError e = frame_error(truth_at(truth, est.stamp_ns), est.pose);
    e.stamp_ns = est.stamp_ns;
    lateral.push_back(e.lateral_m);
    longitudinal.push_back(e.longitudinal_m);
    heading_deg.push_back(e.heading_rad * kDegPerRad);
    position.push_back(e.position_m);
    // `!(a <= b)` so a NaN error becomes the worst frame rather than being skipped.
    if (run.errors.empty() || !(e.position_m <= m.max_position_error_m)) {
      m.max_position_error_m = e.position_m;
      m.worst_frame_stamp_ns = e.stamp_ns;
    }
    m.max_lateral_m = std::max(m.max_lateral_m, std::abs(e.lateral_m));
    m.max_longitudinal_m = std::max(m.max_longitudinal_m, std::abs(e.longitudinal_m));
    m.max_heading_deg = std::max(m.max_heading_deg, std::abs(e.heading_rad) * kDegPerRad);
    run.errors.push_back(e);
    run.estimate_index.push_back(i);
  }
  m.frames = run.errors.size();
  m.lateral_rmse_m = rmse(lateral);
  m.longitudinal_rmse_m = rmse(longitudinal);
  m.heading_rmse_deg = rmse(heading_deg);
  m.position_rmse_m = rmse(position);
  m.latency_p50_ms = percentile_nearest_rank(latency, kMedianPercent);
  m.latency_p99_ms = percentile_nearest_rank(latency, kTailPercent);
  m.latency_max_ms = latency.empty() ? kNaN : *std::max_element(latency.begin(), latency.end());
  const Coverage coverage = estimate_coverage(truth, estimates, scan_period_ns);
  m.coverage = coverage.fraction;
  m.largest_gap_s = coverage.largest_gap_s;
  if (m.frames == 0) {
    m.max_position_error_m = m.max_lateral_m = m.max_longitudinal_m = m.max_heading_deg = kNaN;
    m.failures.push_back(estimates.empty() ? "no estimates" : "no estimates within the ground truth's time range");
  } else {
    check(m, "lateral RMSE", m.lateral_rmse_m, thresholds.lateral_rmse_m, "m");
    check(m, "longitudinal RMSE", m.longitudinal_rmse_m, thresholds.longitudinal_rmse_m, "m");
    check(m, "heading RMSE", m.heading_rmse_deg, thresholds.heading_rmse_deg, "deg");
    check(m, "max position error", m.max_position_error_m, thresholds.max_position_error_m, "m");
    check_at_least(m, "coverage", m.coverage, thresholds.min_coverage);
  }
  double lane_offset = truth.empty() ? kNaN : 0.0;
  for (double offset : lane_offsets(truth, route)) lane_offset = std::max(lane_offset, std::abs(offset));
  m.max_lane_offset_m = lane_offset;
  check(m, "lane offset", m.max_lane_offset_m, thresholds.max_lane_offset_m, "m");
  const CurbOcclusion occlusion = curb_occlusion(curb_visibility);
  m.curb_hidden_fraction = occlusion.hidden_fraction;
  m.curb_hidden_fraction_max = occlusion.hidden_fraction_max;
  m.pass = m.failures.empty();
  return run;
}

}  // namespace lidarloop
