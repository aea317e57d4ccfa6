#pragma once
// Scoring as a pure function: from the trajectories (the ground truth, the localizer's estimates and
// the route the ego was told to follow) and a scenario's thresholds to metrics, per-frame errors and
// a verdict. Nothing here writes files, prints or keeps state; loop/result_files, loop/error_plots
// and loop/run_outputs write what it returns.
//
// The error convention. Each estimate is compared with the truth interpolated at the estimate's
// stamp, in the ground-truth vehicle frame (x forward, y left), with (dx, dy) the estimate's position
// minus the truth's:
//   e_long = cos(psi_gt) dx + sin(psi_gt) dy    positive: ahead of the truth
//   e_lat  = -sin(psi_gt) dx + cos(psi_gt) dy   positive: to its left
//   e_yaw  = wrap(psi_est - psi_gt)             positive: turned counter-clockwise from it
// There is no trajectory alignment: the localizer estimates in the map's frame, which is the truth's,
// so an offset between the two is an error to report, not a nuisance to fit away.
//
// Consistency: does the estimate's covariance P (x, y, yaw in the map frame) claim the accuracy it
// has? Its x-y block is rotated into the same truth vehicle frame, with R = R(psi_gt) the rotation
// from that frame to the map's:
//   P_vehicle = R^T P_xy R,  R = [c -s; s c],  c = cos(psi_gt), s = sin(psi_gt), whose diagonal is
//   s_long^2 = c^2 Pxx + 2 c s Pxy + s^2 Pyy,  s_lat^2 = s^2 Pxx - 2 c s Pxy + c^2 Pyy,  s_yaw^2 = P(2,2)
// and each axis' normalised estimation error squared is NEES = e^2 / s^2 (e_lat^2 / s_lat^2, ...). For a
// filter whose covariance is honest, each NEES is chi-square with one degree of freedom: mean 1, and
// |e| > 3 s in 0.27 % of frames. Metrics average it per axis over the scored frames that are not
// `lost` and whose variance on that axis is positive, beyond the rotation's round-off (NaN when there
// are none: a TUM estimate has no covariance). A mean of 4 says the covariance claims twice the
// accuracy the estimate has.
//
// Integrity: a frame is misleading when its estimate is not `lost` and its error exceeds a protection
// bound it gave, |e_lat| > protection_lateral_m or |e_long| > protection_longitudinal_m (a frame
// without both bounds, NaN, is neither misleading nor counted; an infinite bound is never exceeded).
// It is available when it is not `lost` and both its bounds are under the scenario's alert limits
// (PassThresholds). Both count every scored frame, the ones right after a fault included: those are
// the frames integrity is about, with one exception, integrity's time to alert: a fault (a kidnap, a
// GPS jump) the localizer cannot see before its next observations disagree, and for which it raised
// `lost` within the recovery's lost_within_s, leaves the frames from the fault to that alert awaiting
// it. They are counted apart (misleading_awaiting_alert) and kept out of the misleading fraction and
// of NEES, which judge the filter on the model it has; a localizer that alerts late or never has all
// of them counted.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/curb_visibility.hpp"
#include "common/map_observation.hpp"
#include "common/vehicle_messages.hpp"
#include "scoring/observation_consistency.hpp"
#include "sim/path.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

// ---- What goes in (besides the route, a sim/path.hpp Path, and the scenario's PassThresholds) ----

// Ground truth, typically 100 Hz, sorted by stamp.
using TruthPose = PoseStamped;

// One output of the localizer under test, typically one per scan.
struct EstimateRecord {
  int64_t stamp_ns = 0;
  Pose2d pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // x, y (m), yaw (rad)
  std::string status;                                    // the method's own word ("tracking", "gps only", ...)
  // Wall time the localizer spent on this frame; NaN when not known (an estimate read from a file),
  // and the latency metrics are then null rather than an invented 0.
  double latency_ms = std::numeric_limits<double>::quiet_NaN();
  // The run's first scan: its latency includes the localizer's start-up (an outside program starting
  // and loading its map), so it is reported apart from the others'.
  bool first_scan = false;
  // The localizer's own word that it is lost (its pose is not to be trusted): such a frame is never
  // counted as misleading. False when not known.
  bool lost = false;
  // Protection bounds (m): the lateral and longitudinal error the localizer says this estimate stays
  // within at its stated probability; NaN when not given (an estimate read from a file without them).
  double protection_lateral_m = std::numeric_limits<double>::quiet_NaN();
  double protection_longitudinal_m = std::numeric_limits<double>::quiet_NaN();
  // The LiDAR's mount yaw against the nominal mount as the localizer has learnt it, and its 1 sigma
  // (deg); NaN from a localizer that does not learn it.
  double mount_yaw_deg = std::numeric_limits<double>::quiet_NaN();
  double mount_yaw_sigma_deg = std::numeric_limits<double>::quiet_NaN();
  // The map observations the localizer's filter took for this estimate, when it says (a built-in one).
  std::optional<MapObservation> pose_observation, intensity_observation;
};

// A moment a localizer must recover from: the start of the run, a GPS jump, a kidnap (the scenario's
// faults). The scorer measures how long after it the error settles and `lost` is raised and cleared.
struct FaultEvent {
  int64_t stamp_ns = 0;
  std::string what;  // "start", "gps jump", "gps jump back", "kidnap"
};

// And, for the run's occlusion, the simulator's per-scan curb visibility (common/curb_visibility.hpp):
// measured in the true scene, only summed here.

// ---- What comes out ----

// The error of one estimate, by the convention above. The poses compared are kept for files and plots.
struct FrameError {
  int64_t stamp_ns = 0;
  double lateral_m = 0, longitudinal_m = 0, heading_rad = 0, position_m = 0;
  Pose2d truth, estimate;
  // What the estimate claims about itself on the same axes: its standard deviations in the truth's
  // vehicle frame (NaN where the variance is not positive), its protection bounds and `lost`.
  double sigma_lateral_m = std::numeric_limits<double>::quiet_NaN();
  double sigma_longitudinal_m = std::numeric_limits<double>::quiet_NaN();
  double sigma_heading_rad = std::numeric_limits<double>::quiet_NaN();
  double protection_lateral_m = std::numeric_limits<double>::quiet_NaN();
  double protection_longitudinal_m = std::numeric_limits<double>::quiet_NaN();
  bool lost = false;
  bool awaiting_alert = false;  // after a fault, before the `lost` raised in time for it (above)
};

// The consistency of a run's covariance (the convention above); NaN where no frame counts.
struct Consistency {
  double mean_nees_lateral = std::numeric_limits<double>::quiet_NaN();
  double mean_nees_longitudinal = std::numeric_limits<double>::quiet_NaN();
  double mean_nees_heading = std::numeric_limits<double>::quiet_NaN();
  // Share of the frames counted on an axis whose error is beyond 3 sigma on it; `any`: of the frames
  // with all three variances positive, those beyond 3 sigma on at least one axis.
  double beyond_3_sigma_lateral = std::numeric_limits<double>::quiet_NaN();
  double beyond_3_sigma_longitudinal = std::numeric_limits<double>::quiet_NaN();
  double beyond_3_sigma_heading = std::numeric_limits<double>::quiet_NaN();
  double beyond_3_sigma_any = std::numeric_limits<double>::quiet_NaN();
  size_t frames = 0;  // not lost, all three variances positive
};

// Integrity (the convention above).
struct Integrity {
  size_t frames_with_bounds = 0;  // scored frames giving both protection bounds (infinite ones too)
  size_t misleading_frames = 0;
  double misleading_fraction = std::numeric_limits<double>::quiet_NaN();  // of frames_with_bounds
  // Frames awaiting an alert given in time, with both bounds, and those of them misleading: in none of
  // the figures above.
  size_t frames_awaiting_alert = 0, misleading_awaiting_alert = 0;
  double availability = std::numeric_limits<double>::quiet_NaN();  // of all scored frames
};

// How the localizer came back from one event, each time in seconds from the event and measured on
// the estimates from it until the next event (or the end), with the error each has whether it is
// scored or settling; NaN when it did not happen in that window.
struct EventRecovery {
  FaultEvent event;
  // To the first estimate from which the position error stays under recovery's position_m.
  double converged_after_s = std::numeric_limits<double>::quiet_NaN();
  // To the first estimate saying `lost`, and to the first after that one not saying it.
  double lost_raised_after_s = std::numeric_limits<double>::quiet_NaN();
  double lost_cleared_after_s = std::numeric_limits<double>::quiet_NaN();
};

// The accuracy figures against the run's reference (scoring/reference_trajectory.hpp) rather than the
// exact truth: each estimate's error by the same convention with the reference, interpolated at its
// stamp, in the truth's place (in the reference's vehicle frame, as a real experiment has no other), on
// the same frames as Metrics' own figures (scored, not settling, not recovering).
struct ReferenceAccuracy {
  ReferenceConfig config;  // what was drawn (a label: the scorer is given the poses)
  double lateral_rmse_m = std::numeric_limits<double>::quiet_NaN();
  double longitudinal_rmse_m = std::numeric_limits<double>::quiet_NaN();
  double heading_rmse_deg = std::numeric_limits<double>::quiet_NaN();
  double position_rmse_m = std::numeric_limits<double>::quiet_NaN();
  double max_position_error_m = std::numeric_limits<double>::quiet_NaN();  // absolute, as Metrics'
  double max_lateral_m = std::numeric_limits<double>::quiet_NaN();
  double max_longitudinal_m = std::numeric_limits<double>::quiet_NaN();
  double max_heading_deg = std::numeric_limits<double>::quiet_NaN();
  // The reference's own error against the truth on those frames, by the same convention (RMS): what it
  // adds to, or takes from, the figures above.
  double error_lateral_rms_m = std::numeric_limits<double>::quiet_NaN();
  double error_longitudinal_rms_m = std::numeric_limits<double>::quiet_NaN();
  double error_heading_rms_deg = std::numeric_limits<double>::quiet_NaN();
};

// What a localizer that learns the LiDAR's mount yaw (EstimateRecord::mount_yaw_deg) made of it,
// against the run's draw.
struct MountYawMetrics {
  double drawn_deg = 0;
  double learnt_deg = 0, sigma_deg = 0;  // the last estimate's
  double error_deg = 0;                  // learnt - drawn
  // The time from the first estimate after which every estimate's learnt yaw lies within tolerance_deg
  // of the drawn one; unset if the last one does not.
  std::optional<double> settled_s;
  double tolerance_deg = 0;
};

struct Metrics {
  std::string method, scenario;
  // The run's realism profile and the knobs the scenario set on top of it (labels, not scored).
  std::string realism;
  std::vector<std::string> realism_overrides;
  // This run's draw of the true LiDAR mount against the nominal one the localizer is given: roll,
  // pitch, yaw (deg) and x, y, z (m).
  Eigen::Vector3d mount_error_rpy_deg = Eigen::Vector3d::Zero(), mount_error_xyz_m = Eigen::Vector3d::Zero();
  size_t frames = 0;           // estimates scored
  size_t unscored_frames = 0;  // estimates outside the truth's time range (not scored, reported)
  size_t settling_frames = 0;  // estimates within thresholds.settle_s of the first (not scored)
  // With thresholds.recovery set, the scored estimates within its within_s after a fault (not the
  // start, which settle_s covers): kept out of the RMSEs and maxima, counted in consistency and integrity.
  size_t recovery_frames = 0;
  double lateral_rmse_m = 0, longitudinal_rmse_m = 0, heading_rmse_deg = 0, position_rmse_m = 0;
  double max_position_error_m = 0, max_lateral_m = 0, max_longitudinal_m = 0, max_heading_deg = 0;  // absolute
  int64_t worst_frame_stamp_ns = 0;  // the frame with the largest position error (for a bird's-eye plot)
  double latency_p50_ms = 0, latency_p99_ms = 0, latency_max_ms = 0;  // over every known latency; NaN: none
  double latency_first_scan_ms =
      std::numeric_limits<double>::quiet_NaN();  // the first scan's, not in the three above; NaN: not known
  // How much of the truth's time span the estimates cover, and the longest stretch they leave
  // uncovered, by the definition of estimate_coverage() below; NaN without a truth span.
  double coverage = std::numeric_limits<double>::quiet_NaN();
  double largest_gap_s = std::numeric_limits<double>::quiet_NaN();
  // The truth's largest distance from the route (its lane's centre) over the whole run; NaN without truth.
  double max_lane_offset_m = std::numeric_limits<double>::quiet_NaN();
  // How much of the curb in the localizer's range the traffic hid: hidden / (hidden + visible) curb
  // samples over every scan of the run, and the worst scan's. NaN when no sample was ever in range (or
  // the run's visibility is not known, as in a replayed log without it).
  double curb_hidden_fraction = std::numeric_limits<double>::quiet_NaN();
  double curb_hidden_fraction_max = std::numeric_limits<double>::quiet_NaN();
  // Against the run's reference, when it has one (the scenario's `reference`); unset: the truth only.
  std::optional<ReferenceAccuracy> reference;
  Consistency consistency;
  Integrity integrity;
  std::vector<EventRecovery> recovery;       // one per event given to score(), in time order
  std::optional<MountYawMetrics> mount_yaw;  // from a localizer that learns it
  // Its map observations against the truth (scoring/observation_consistency.hpp), when it gives them:
  // the curbs' or the point cloud's pose, and APS's position.
  std::optional<ObservationConsistency> pose_observations, intensity_observations;
  PassThresholds thresholds;
  bool pass = false;
  std::vector<std::string> failures;  // for people, e.g. "lateral RMSE 0.310 m > 0.200 m"
};

struct ScoredRun {
  Metrics metrics;
  std::vector<FrameError> errors;      // one per scored estimate, in the estimates' order
  std::vector<size_t> estimate_index;  // errors[i] belongs to estimates[estimate_index[i]]
};

// ---- The scorer ----

// The two kinds of estimate score() keeps out of the RMSEs and the maxima (see Metrics): settling, within
// thresholds.settle_s of the first estimate; recovering, with thresholds.recovery set, within its
// within_s after one of `events` other than the start. The run's worst-frame picture uses the same.
bool settling(int64_t stamp_ns, int64_t first_estimate_ns, const PassThresholds& thresholds);
bool recovering(int64_t stamp_ns, const PassThresholds& thresholds, const std::vector<FaultEvent>& events);

// Scores every estimate whose stamp lies within the truth's time range and after the settling time
// (counted from the first estimate, scored or not), and measures the truth's lane keeping along
// `route`. The estimates are aligned to the truth by time stamp only: the truth is interpolated at
// each estimate's stamp, never the estimate, and there is no spatial alignment. So an estimate that
// starts late, stops early or has gaps is scored on what exists; its coverage (estimate_coverage,
// with the LiDAR's nominal `scan_period_ns`) says how much that is. `method` and `scenario` only
// label the metrics. Passes when there is at least one scored frame and every threshold that is set
// holds (a non-finite value never holds). Throws std::invalid_argument if the truth is not sorted by
// stamp or the route has fewer than two points. `curb_visibility` (one record per scan, any order)
// gives the curb occlusion figures; it is not scored against any threshold. `events` (any order;
// loop/fault_events.hpp's from a scenario) give the recovery figures, by thresholds.recovery's
// criteria or, unset, its defaults, and, when it is set, the recovery frames. `reference` (the truth's
// stamps, scoring/reference_trajectory.hpp), when not empty, gives Metrics::reference (its config left
// default for the caller to label) and, with thresholds.against_reference, the poses the accuracy
// thresholds are checked against; empty with against_reference is a failure. Throws
// std::invalid_argument when a non-empty reference's stamps are not the truth's.
ScoredRun score(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates, const Path& route,
                const PassThresholds& thresholds, const std::string& method, const std::string& scenario,
                const std::vector<FaultEvent>& events = {}, const std::vector<CurbVisibility>& curb_visibility = {},
                int64_t scan_period_ns = Hdl32eConfig{}.scan_period_ns(), const std::vector<TruthPose>& reference = {});

// ---- Its parts, pure as well ----

// The mount yaw a localizer learnt against the drawn one (deg); unset when no estimate carries one.
std::optional<MountYawMetrics> mount_yaw_metrics(const std::vector<EstimateRecord>& estimates, double drawn_deg,
                                                 double tolerance_deg);

// The error of `estimate` against `truth` by the convention above; stamp_ns is left 0 for the caller
// and the estimate's claims NaN (not given).
FrameError frame_error(const Pose2d& truth, const Pose2d& estimate);
// The same with the estimate's stamp and its claims (sigmas in the truth's frame, bounds, `lost`).
FrameError estimate_error(const Pose2d& truth, const EstimateRecord& estimate);

// e^2 / sigma^2; NaN when sigma is not positive (no variance claimed) or either is not finite.
double nees(double error, double sigma);

// Integrity of one frame and of a run, by the convention above.
bool misleading(const FrameError& frame);
bool available(const FrameError& frame, double alert_limit_lateral_m, double alert_limit_longitudinal_m);
Integrity integrity(const std::vector<FrameError>& frames, double alert_limit_lateral_m,
                    double alert_limit_longitudinal_m);
Consistency consistency(const std::vector<FrameError>& frames);

// One EventRecovery per event, in time order, from `frames` (sorted by stamp, each estimate in the
// truth's range); `position_m` is the error a recovered estimate stays under.
// Marks the frames awaiting an alert given in time (the integrity convention above): for each fault
// whose `lost` was raised within time_to_alert_s, those from the fault to the alert.
void mark_awaiting_alert(std::vector<FrameError>& frames, const std::vector<EventRecovery>& recovery,
                         double time_to_alert_s);
std::vector<EventRecovery> event_recovery(const std::vector<FrameError>& frames, std::vector<FaultEvent> events,
                                          double position_m);

// Truth at t by linear interpolation between the bracketing samples, the yaw interpolated along the
// shorter arc. `truth` must be sorted by stamp. Throws std::out_of_range if t lies outside
// [first stamp, last stamp] or truth is empty: extrapolating would invent a ground truth.
Pose2d truth_at(const std::vector<TruthPose>& truth, int64_t t_ns);

// Each truth sample's signed distance from `route` (positive = left of its direction of travel),
// measured square to the route at the sample's projection. The projection follows the car along the
// route from where the previous sample was, so it cannot jump to another stretch that passes nearby;
// on a closed route its arc length runs on unwrapped, lap after lap, as the car's does; an open route
// ends where it ends (beyond it, the distance is to the line of its last segment). The first sample
// is projected onto the whole route. Throws std::invalid_argument if the route has fewer than two
// points.
std::vector<double> lane_offsets(const std::vector<TruthPose>& truth, const Path& route);

// The curb occlusion of a run (Metrics::curb_hidden_fraction and _max) from its per-scan records.
struct CurbOcclusion {
  double hidden_fraction = std::numeric_limits<double>::quiet_NaN();
  double hidden_fraction_max = std::numeric_limits<double>::quiet_NaN();  // over scans with a sample in range
};
CurbOcclusion curb_occlusion(const std::vector<CurbVisibility>& scans);

// Coverage. Each estimate covers the time within half a nominal scan period of its stamp
// ([t - P/2, t + P/2], P = `scan_period_ns`, 100 ms for the HDL-32E at 10 Hz), so an estimate per
// scan covers time without a hole however its stamps fall within the scan. The reference is the
// truth's time span [first truth stamp, last truth stamp] (the drive, from its first to its last
// instant):
//   fraction      = |union of the estimates' intervals within the span| / |span|
//   largest_gap_s = the longest stretch of the span in no estimate's interval, before the first
//                   estimate and after the last included (0 when the span is covered; one missed
//                   scan in a 10 Hz stream is a gap of one period)
// A live run's estimates cover all but the first scans before the localizer is initialised. Both
// NaN when the truth spans no time. The estimates' order does not matter.
struct Coverage {
  double fraction = std::numeric_limits<double>::quiet_NaN();
  double largest_gap_s = std::numeric_limits<double>::quiet_NaN();
};
Coverage estimate_coverage(const std::vector<TruthPose>& truth, const std::vector<EstimateRecord>& estimates,
                           int64_t scan_period_ns);

// Root mean square; NaN for an empty list (there is nothing to measure, and 0 would read as perfect).
double rmse(const std::vector<double>& values);

// Nearest-rank percentile: the smallest value such that at least `percent` % of the values are less
// than or equal to it, i.e. sorted[ceil(percent / 100 * n) - 1] (the first value for percent = 0).
// Always one of the values, never an interpolation. NaN for an empty list.
double percentile_nearest_rank(std::vector<double> values, double percent);

}  // namespace lidarloop
