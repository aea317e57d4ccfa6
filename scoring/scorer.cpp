#include "scoring/scorer.hpp"

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
// The consistency bound: a Gaussian error beyond 3 sigma has a probability of 0.27 %.
constexpr double kSigmaBound = 3.0;
constexpr double kPercent = 100.0;
// A rotated variance under this share of the x-y block's is round-off (cos^2 90 deg = 4e-33): no filter
// claims a sigma a millionth of its other axis'.
constexpr double kRotationRoundOff = 1e-12;

double seconds_between(int64_t from_ns, int64_t to_ns) { return double(to_ns - from_ns) / double(kNsPerS); }

std::string fixed3(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", value);
  return text;
}

// "lateral RMSE 0.310 m > 0.200 m". Millimetre (millidegree) digits so a value just over its
// threshold never prints as equal to it.
std::string failure(const char* what, double value, double threshold, const char* unit) {
  const std::string u = *unit ? std::string(" ") + unit : "";  // a ratio such as NEES has no unit
  return std::string(what) + " " + fixed3(value) + u + " > " + fixed3(threshold) + u;
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

// Every recovery criterion for one event, e.g. "kidnap at 10.00 s: converged after 4.200 s > 3.000 s".
void check_recovery(Metrics& m, const EventRecovery& r, const PassThresholds::Recovery& criteria) {
  char at[64];
  std::snprintf(at, sizeof at, "%s at %.2f s: ", r.event.what.c_str(), double(r.event.stamp_ns) / double(kNsPerS));
  const std::string prefix = at;
  if (!std::isfinite(r.converged_after_s))
    m.failures.push_back(prefix + "the position error never stayed under " + fixed3(criteria.position_m) + " m");
  else
    check(m, (prefix + "converged after").c_str(), r.converged_after_s, criteria.within_s, "s");
  // A cold start may be lost from its first frame; a GPS fix jumping back to the truth need not make
  // anyone lost (fault_events.hpp). Either must still clear a `lost` it raised.
  const bool must_raise = r.event.what != "start" && r.event.what != "gps jump back";
  if (must_raise && !std::isfinite(r.lost_raised_after_s))
    m.failures.push_back(prefix + "lost was never raised");
  else if (must_raise)
    check(m, (prefix + "lost raised after").c_str(), r.lost_raised_after_s, criteria.lost_within_s, "s");
  if (std::isfinite(r.lost_raised_after_s) && !std::isfinite(r.lost_cleared_after_s))
    m.failures.push_back(prefix + "lost was never cleared");
}

// The accuracy figures of a run (Metrics' RMSEs and maxima) from its frames, in the order given.
struct AccuracyTally {
  std::vector<double> lateral, longitudinal, heading_deg, position;
  double max_position_error_m = 0, max_lateral_m = 0, max_longitudinal_m = 0, max_heading_deg = 0;
  int64_t worst_frame_stamp_ns = 0;

  void add(const FrameError& e) {
    lateral.push_back(e.lateral_m);
    longitudinal.push_back(e.longitudinal_m);
    heading_deg.push_back(e.heading_rad * kDegPerRad);
    position.push_back(e.position_m);
    // `!(a <= b)` so a NaN error becomes the worst frame rather than being skipped.
    if (position.size() == 1 || !(e.position_m <= max_position_error_m)) {
      max_position_error_m = e.position_m;
      worst_frame_stamp_ns = e.stamp_ns;
    }
    max_lateral_m = std::max(max_lateral_m, std::abs(e.lateral_m));
    max_longitudinal_m = std::max(max_longitudinal_m, std::abs(e.longitudinal_m));
    max_heading_deg = std::max(max_heading_deg, std::abs(e.heading_rad) * kDegPerRad);
  }
};

// Metrics' or ReferenceAccuracy's figures from a tally; the maxima NaN without a frame.
template <typename Figures>
void set_accuracy(Figures& f, const AccuracyTally& t) {
  f.lateral_rmse_m = rmse(t.lateral);
  f.longitudinal_rmse_m = rmse(t.longitudinal);
  f.heading_rmse_deg = rmse(t.heading_deg);
  f.position_rmse_m = rmse(t.position);
  const bool none = t.position.empty();
  f.max_position_error_m = none ? kNaN : t.max_position_error_m;
  f.max_lateral_m = none ? kNaN : t.max_lateral_m;
  f.max_longitudinal_m = none ? kNaN : t.max_longitudinal_m;
  f.max_heading_deg = none ? kNaN : t.max_heading_deg;
}

// The reference must be drawn at the truth's samples: interpolating it elsewhere would blend two
// draws the scorer never chose.
void check_reference_stamps(const std::vector<TruthPose>& truth, const std::vector<TruthPose>& reference) {
  const bool same = reference.size() == truth.size() &&
                    std::equal(truth.begin(), truth.end(), reference.begin(),
                               [](const TruthPose& a, const TruthPose& b) { return a.stamp_ns == b.stamp_ns; });
  if (!same) throw std::invalid_argument("score: the reference's stamps are not the ground truth's");
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

FrameError estimate_error(const Pose2d& truth, const EstimateRecord& estimate) {
  FrameError e = frame_error(truth, estimate.pose);
  e.stamp_ns = estimate.stamp_ns;
  const Eigen::Matrix3d& p = estimate.covariance;
  const double c = std::cos(truth.yaw), s = std::sin(truth.yaw);
  // The diagonal of R^T P_xy R (the header's convention). A variance that is not positive claims
  // nothing, nor does one that is only the rotation's round-off of the block's variance (cos 90 deg is
  // 6e-17, not 0).
  const double round_off = kRotationRoundOff * (std::abs(p(0, 0)) + std::abs(p(1, 1)));
  auto sigma = [](double variance, double floor) { return variance > floor ? std::sqrt(variance) : kNaN; };
  e.sigma_longitudinal_m = sigma(c * c * p(0, 0) + 2 * c * s * p(0, 1) + s * s * p(1, 1), round_off);
  e.sigma_lateral_m = sigma(s * s * p(0, 0) - 2 * c * s * p(0, 1) + c * c * p(1, 1), round_off);
  e.sigma_heading_rad = sigma(p(2, 2), 0.0);
  e.protection_lateral_m = estimate.protection_lateral_m;
  e.protection_longitudinal_m = estimate.protection_longitudinal_m;
  e.lost = estimate.lost;
  return e;
}

double nees(double error, double sigma) {
  if (!(sigma > 0) || !std::isfinite(sigma) || !std::isfinite(error)) return kNaN;
  return error * error / (sigma * sigma);
}

bool misleading(const FrameError& f) {
  // `>` is false for a NaN bound, so a frame without one is never misleading.
  return !f.lost &&
         (std::abs(f.lateral_m) > f.protection_lateral_m || std::abs(f.longitudinal_m) > f.protection_longitudinal_m);
}

bool available(const FrameError& f, double alert_limit_lateral_m, double alert_limit_longitudinal_m) {
  return !f.lost && f.protection_lateral_m < alert_limit_lateral_m &&
         f.protection_longitudinal_m < alert_limit_longitudinal_m;
}

Integrity integrity(const std::vector<FrameError>& frames, double alert_limit_lateral_m,
                    double alert_limit_longitudinal_m) {
  Integrity in;
  size_t available_frames = 0;
  for (const FrameError& f : frames) {
    // An infinite bound (a lost localizer's "anywhere") is a bound; NaN is none given.
    if (!std::isnan(f.protection_lateral_m) && !std::isnan(f.protection_longitudinal_m)) {
      if (f.awaiting_alert) {
        ++in.frames_awaiting_alert;
        in.misleading_awaiting_alert += misleading(f);
      } else {
        ++in.frames_with_bounds;
        in.misleading_frames += misleading(f);
      }
    }
    available_frames += available(f, alert_limit_lateral_m, alert_limit_longitudinal_m);
  }
  if (in.frames_with_bounds > 0) in.misleading_fraction = double(in.misleading_frames) / double(in.frames_with_bounds);
  if (!frames.empty()) in.availability = double(available_frames) / double(frames.size());
  return in;
}

Consistency consistency(const std::vector<FrameError>& frames) {
  struct Axis {
    double nees_sum = 0;
    size_t frames = 0, beyond = 0;
    void add(double value) {  // one frame's NEES, NaN when the frame claims no variance on the axis
      if (!std::isfinite(value)) return;
      nees_sum += value;
      ++frames;
      beyond += value > kSigmaBound * kSigmaBound;
    }
    double mean() const { return frames ? nees_sum / double(frames) : kNaN; }
    double beyond_fraction() const { return frames ? double(beyond) / double(frames) : kNaN; }
  } lateral, longitudinal, heading, any;
  for (const FrameError& f : frames) {
    if (f.lost || f.awaiting_alert) continue;
    const double n_lat = nees(f.lateral_m, f.sigma_lateral_m), n_long = nees(f.longitudinal_m, f.sigma_longitudinal_m),
                 n_yaw = nees(f.heading_rad, f.sigma_heading_rad);
    lateral.add(n_lat);
    longitudinal.add(n_long);
    heading.add(n_yaw);
    // The largest of the three is beyond 3 sigma exactly when one axis is; NaN unless all three count.
    if (std::isfinite(n_lat + n_long + n_yaw)) any.add(std::max({n_lat, n_long, n_yaw}));
  }
  Consistency c;
  c.mean_nees_lateral = lateral.mean();
  c.mean_nees_longitudinal = longitudinal.mean();
  c.mean_nees_heading = heading.mean();
  c.beyond_3_sigma_lateral = lateral.beyond_fraction();
  c.beyond_3_sigma_longitudinal = longitudinal.beyond_fraction();
  c.beyond_3_sigma_heading = heading.beyond_fraction();
  c.beyond_3_sigma_any = any.beyond_fraction();
  c.frames = any.frames;
  return c;
}

std::vector<EventRecovery> event_recovery(const std::vector<FrameError>& frames, std::vector<FaultEvent> events,
                                          double position_m) {
  std::stable_sort(events.begin(), events.end(),
                   [](const FaultEvent& a, const FaultEvent& b) { return a.stamp_ns < b.stamp_ns; });
  std::vector<EventRecovery> out;
  for (size_t k = 0; k < events.size(); ++k) {
    EventRecovery r{events[k]};
    const int64_t from = events[k].stamp_ns;
    const int64_t until = k + 1 < events.size() ? events[k + 1].stamp_ns : std::numeric_limits<int64_t>::max();
    std::optional<int64_t> recovered, raised, cleared;  // stamps
    for (const FrameError& f : frames) {
      if (f.stamp_ns < from || f.stamp_ns >= until) continue;
      // `!(a < b)` so a NaN error is not a recovered one.
      if (!(f.position_m < position_m))
        recovered.reset();
      else if (!recovered)
        recovered = f.stamp_ns;
      if (f.lost && !raised) raised = f.stamp_ns;
      if (!f.lost && raised && !cleared) cleared = f.stamp_ns;
    }
    if (recovered) r.converged_after_s = seconds_between(from, *recovered);
    if (raised) r.lost_raised_after_s = seconds_between(from, *raised);
    if (cleared) r.lost_cleared_after_s = seconds_between(from, *cleared);
    out.push_back(r);
  }
  return out;
}

void mark_awaiting_alert(std::vector<FrameError>& frames, const std::vector<EventRecovery>& recovery,
                         double time_to_alert_s) {
  for (const EventRecovery& r : recovery) {
    // The start is no fault: the localizer's first fix is all it has, and it claims no more.
    if (r.event.what == "start" || !(r.lost_raised_after_s <= time_to_alert_s)) continue;
    const int64_t from = r.event.stamp_ns;
    const double until_s = r.lost_raised_after_s;
    for (FrameError& f : frames)
      if (f.stamp_ns >= from && seconds_between(from, f.stamp_ns) < until_s) f.awaiting_alert = true;
  }
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

namespace {
// Where on the route a drive starts: the first stretch (smallest arc length) that passes within half a
// metre of the nearest one and heads the car's way, its nearest point within kReach. An open route that
// comes back through its start (laps joined by U-turns at a map's edge) passes there several times; the
// global nearest may be a later pass.
double starting_arc(const Path& route, const Pose2d& start) {
  constexpr double kStep = 0.5, kSlack = 0.5, kReach = 10;  // m
  const Eigen::Vector2d p(start.x, start.y);
  if (route.closed) return route.project(p);  // one loop, passed once a lap
  const auto distance = [&](double s) {
    const Pose2d on = route.pose_at(s);
    return std::hypot(on.x - p.x(), on.y - p.y());
  };
  const double nearest = distance(route.project(p));
  for (double s = 0; s <= route.length; s += kStep)
    if (distance(s) <= nearest + kSlack && std::cos(route.pose_at(s).yaw - start.yaw) > 0)
      return route.project(p, std::max(0.0, s - kStep), std::min(route.length, s + kReach));
  return route.project(p);
}
}  // namespace

std::vector<double> lane_offsets(const std::vector<TruthPose>& truth, const Path& route) {
  if (route.points.size() < 2) throw std::invalid_argument("lane_offsets: the route has fewer than two points");
  std::vector<double> offsets;
  offsets.reserve(truth.size());
  double s = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Vector2d p(truth[i].pose.x, truth[i].pose.y);
    // The window is not clamped to [0, length]: on a closed route Path::project takes an unwrapped
    // window across the seam and answers unwrapped, so s keeps counting laps; an open route clamps it.
    s = i == 0 ? starting_arc(route, truth[i].pose) : route.project(p, s - kLaneSearch, s + kLaneSearch);
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

bool settling(int64_t stamp_ns, int64_t first_estimate_ns, const PassThresholds& thresholds) {
  return double(stamp_ns - first_estimate_ns) < thresholds.settle_s * double(kNsPerS);
}

// Unset, the recovery criteria's defaults still measure the events, but every frame is scored for
// accuracy: a scenario that only jumps the GPS means the map to carry the car through the jump.
bool recovering(int64_t stamp_ns, const PassThresholds& thresholds, const std::vector<FaultEvent>& events) {
  if (!thresholds.recovery) return false;
  for (const FaultEvent& event : events)
    if (event.what != "start" && stamp_ns >= event.stamp_ns &&
        double(stamp_ns - event.stamp_ns) <= thresholds.recovery->within_s * double(kNsPerS))
      return true;
  return false;
}

ScoredRun score(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates, const Path& route,
                const PassThresholds& thresholds, const std::string& method, const std::string& scenario,
                const std::vector<FaultEvent>& events, const std::vector<CurbVisibility>& curb_visibility,
                int64_t scan_period_ns, const std::vector<TruthPose>& reference) {
  if (!std::is_sorted(truth.begin(), truth.end(),
                      [](const TruthPose& a, const TruthPose& b) { return a.stamp_ns < b.stamp_ns; }))
    throw std::invalid_argument("score: ground truth is not sorted by stamp");
  ScoredRun run;
  Metrics& m = run.metrics;
  m.method = method;
  m.scenario = scenario;
  m.thresholds = thresholds;

  const PassThresholds::Recovery recovery_criteria = thresholds.recovery.value_or(PassThresholds::Recovery{});

  const bool with_reference = !reference.empty();
  if (with_reference) check_reference_stamps(truth, reference);
  AccuracyTally accuracy, against_reference, reference_error;
  std::vector<double> latency;
  std::vector<FrameError> in_range;  // every estimate in the truth's range, settling or not: for recovery
  for (size_t i = 0; i < estimates.size(); ++i) {
    const EstimateRecord& est = estimates[i];
    if (est.first_scan)
      m.latency_first_scan_ms = est.latency_ms;
    else if (std::isfinite(est.latency_ms))
      latency.push_back(est.latency_ms);
    if (truth.empty() || est.stamp_ns < truth.front().stamp_ns || est.stamp_ns > truth.back().stamp_ns) {
      ++m.unscored_frames;
      continue;
    }
    const FrameError e = estimate_error(truth_at(truth, est.stamp_ns), est);
    in_range.push_back(e);
    if (settling(est.stamp_ns, estimates.front().stamp_ns, thresholds)) {
      ++m.settling_frames;
      continue;
    }
    run.errors.push_back(e);
    run.estimate_index.push_back(i);
    if (recovering(e.stamp_ns, thresholds, events)) {
      ++m.recovery_frames;
      continue;
    }
    accuracy.add(e);
    if (with_reference) {
      const Pose2d at_reference = truth_at(reference, est.stamp_ns);
      against_reference.add(frame_error(at_reference, est.pose));
      reference_error.add(frame_error(e.truth, at_reference));
    }
  }
  m.frames = run.errors.size();
  std::sort(in_range.begin(), in_range.end(),
            [](const FrameError& a, const FrameError& b) { return a.stamp_ns < b.stamp_ns; });
  m.recovery = event_recovery(in_range, events, recovery_criteria.position_m);
  mark_awaiting_alert(run.errors, m.recovery, recovery_criteria.lost_within_s);
  m.consistency = consistency(run.errors);
  m.integrity = integrity(run.errors, thresholds.alert_limit_lateral_m, thresholds.alert_limit_longitudinal_m);
  set_accuracy(m, accuracy);
  m.worst_frame_stamp_ns = accuracy.worst_frame_stamp_ns;
  if (with_reference) {
    ReferenceAccuracy r;
    set_accuracy(r, against_reference);
    r.error_lateral_rms_m = rmse(reference_error.lateral);
    r.error_longitudinal_rms_m = rmse(reference_error.longitudinal);
    r.error_heading_rms_deg = rmse(reference_error.heading_deg);
    m.reference = r;
  }
  m.latency_p50_ms = percentile_nearest_rank(latency, kMedianPercent);
  m.latency_p99_ms = percentile_nearest_rank(latency, kTailPercent);
  m.latency_max_ms = latency.empty() ? kNaN : *std::max_element(latency.begin(), latency.end());
  const Coverage coverage = estimate_coverage(truth, estimates, scan_period_ns);
  m.coverage = coverage.fraction;
  m.largest_gap_s = coverage.largest_gap_s;
  if (m.frames == 0) {
    m.failures.push_back(estimates.empty() ? "no estimates" : "no estimates within the ground truth's time range");
  } else if (thresholds.against_reference && !m.reference) {
    m.failures.push_back("the accuracy thresholds are against the reference, but the run has none");
  } else if (thresholds.against_reference) {
    const ReferenceAccuracy& r = *m.reference;
    check(m, "lateral RMSE against the reference", r.lateral_rmse_m, thresholds.lateral_rmse_m, "m");
    check(m, "longitudinal RMSE against the reference", r.longitudinal_rmse_m, thresholds.longitudinal_rmse_m, "m");
    check(m, "heading RMSE against the reference", r.heading_rmse_deg, thresholds.heading_rmse_deg, "deg");
    check(m, "max position error against the reference", r.max_position_error_m, thresholds.max_position_error_m, "m");
  } else {
    check(m, "lateral RMSE", m.lateral_rmse_m, thresholds.lateral_rmse_m, "m");
    check(m, "longitudinal RMSE", m.longitudinal_rmse_m, thresholds.longitudinal_rmse_m, "m");
    check(m, "heading RMSE", m.heading_rmse_deg, thresholds.heading_rmse_deg, "deg");
    check(m, "max position error", m.max_position_error_m, thresholds.max_position_error_m, "m");
  }
  if (m.frames > 0) {
    check_at_least(m, "coverage", m.coverage, thresholds.min_coverage);
    const Consistency& c = m.consistency;
    for (const auto& [axis, mean] :
         {std::pair{"lateral", c.mean_nees_lateral}, std::pair{"longitudinal", c.mean_nees_longitudinal},
          std::pair{"heading", c.mean_nees_heading}}) {
      const std::string what = std::string("mean NEES ") + axis;
      check_at_least(m, what.c_str(), mean, thresholds.min_mean_nees);
      check(m, what.c_str(), mean, thresholds.max_mean_nees, "");
    }
    const std::optional<double> misleading_percent = thresholds.max_misleading_fraction
                                                         ? std::optional(kPercent * *thresholds.max_misleading_fraction)
                                                         : std::nullopt;
    check(m, "misleading frames", kPercent * m.integrity.misleading_fraction, misleading_percent, "%");
    check_at_least(m, "availability", m.integrity.availability, thresholds.min_availability);
    if (thresholds.recovery)
      for (const EventRecovery& r : m.recovery) check_recovery(m, r, *thresholds.recovery);
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

std::optional<MountYawMetrics> mount_yaw_metrics(const std::vector<EstimateRecord>& estimates, double drawn_deg,
                                                 double tolerance_deg) {
  std::optional<MountYawMetrics> m;
  int64_t first_ns = 0, settled_ns = 0;
  bool within = false;
  for (const EstimateRecord& e : estimates) {
    if (!std::isfinite(e.mount_yaw_deg)) continue;
    if (!m) m = MountYawMetrics{drawn_deg, 0, 0, 0, std::nullopt, tolerance_deg}, first_ns = e.stamp_ns;
    m->learnt_deg = e.mount_yaw_deg;
    m->sigma_deg = e.mount_yaw_sigma_deg;
    const bool now = std::abs(e.mount_yaw_deg - drawn_deg) <= tolerance_deg;
    if (now && !within) settled_ns = e.stamp_ns;
    within = now;
  }
  if (!m) return m;
  m->error_deg = m->learnt_deg - drawn_deg;
  if (within) m->settled_s = double(settled_ns - first_ns) / double(kNsPerS);
  return m;
}

}  // namespace lidarloop
