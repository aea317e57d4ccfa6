#pragma once
// Scores a localizer's estimates against ground truth, per DESIGN.md: errors in the ground-truth
// vehicle frame at each estimate's stamp, no trajectory alignment; RMSEs, maxima and latency
// percentiles; pass / fail against a scenario's thresholds.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

// Ground truth, typically 100 Hz, sorted by stamp.
using TruthPose = PoseStamped;

// One output of the localizer under test, typically one per scan.
struct EstimateRecord {
  int64_t stamp_ns = 0;
  Pose2d pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // x, y (m), yaw (rad)
  std::string status;                                    // the method's own word ("tracking", "gps only", ...)
  double latency_ms = 0;                                  // wall time the localizer spent on this frame
};

// The error of one estimate, in the ground-truth vehicle frame (x forward, y left): positive
// longitudinal = ahead of the truth, positive lateral = to its left, positive heading = turned
// counter-clockwise from it. The poses compared are kept for files and plots.
struct FrameError {
  int64_t stamp_ns = 0;
  double lateral_m = 0, longitudinal_m = 0, heading_rad = 0, position_m = 0;
  Pose2d truth, estimate;
};

// DESIGN.md's formulas; stamp_ns is left 0 for the caller to set.
FrameError frame_error(const Pose2d& truth, const Pose2d& estimate);

// Truth at t by linear interpolation between the bracketing samples, the yaw interpolated along the
// shorter arc. `truth` must be sorted by stamp. Throws std::out_of_range if t lies outside
// [first stamp, last stamp] or truth is empty: extrapolating would invent a ground truth.
Pose2d truth_at(const std::vector<TruthPose>& truth, int64_t t_ns);

// Root mean square; NaN for an empty list (there is nothing to measure, and 0 would read as perfect).
double rmse(const std::vector<double>& values);

// Nearest-rank percentile: the smallest value such that at least `percent` % of the values are less
// than or equal to it, i.e. sorted[ceil(percent / 100 * n) - 1] (the first value for percent = 0).
// Always one of the values, never an interpolation. NaN for an empty list.
double percentile_nearest_rank(std::vector<double> values, double percent);

struct Metrics {
  std::string method, scenario;
  size_t frames = 0;            // estimates scored
  size_t unscored_frames = 0;   // estimates outside the truth's time range (not scored, reported)
  size_t settling_frames = 0;   // estimates within thresholds.settle_s of the first (not scored)
  double lateral_rmse_m = 0, longitudinal_rmse_m = 0, heading_rmse_deg = 0, position_rmse_m = 0;
  double max_position_error_m = 0, max_lateral_m = 0, max_longitudinal_m = 0, max_heading_deg = 0;  // absolute
  int64_t worst_frame_stamp_ns = 0;  // the frame with the largest position error (for a bird's-eye plot)
  double latency_p50_ms = 0, latency_p99_ms = 0, latency_max_ms = 0;  // over every estimate
  double max_lane_offset_m = std::numeric_limits<double>::quiet_NaN();  // set by score_lane_keeping
  PassThresholds thresholds;
  bool pass = false;
  std::vector<std::string> failures;  // for people, e.g. "lateral RMSE 0.310 m > 0.200 m"
};

struct ScoredRun {
  Metrics metrics;
  std::vector<FrameError> errors;     // one per scored estimate, in the estimates' order
  std::vector<size_t> estimate_index; // errors[i] belongs to estimates[estimate_index[i]]
};

// Scores every estimate whose stamp lies within the truth's time range. Passes when there is at
// least one scored frame and every threshold that is set holds (a non-finite value never holds).
// Throws std::invalid_argument if the truth is not sorted by stamp.
// The car's largest distance from its lane's centre (closed loop), checked against
// thresholds.max_lane_offset_m; updates pass and failures.
void score_lane_keeping(Metrics& metrics, double max_lane_offset_m);

ScoredRun score(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates,
                const PassThresholds& thresholds, const std::string& method, const std::string& scenario);

}  // namespace lidarloop
