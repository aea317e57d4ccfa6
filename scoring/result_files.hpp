#pragma once
// The files a run's results leave behind, written from what the pure scorer (scoring/scorer.hpp)
// returned: metrics.json for machines, errors.csv per frame, TUM trajectories for evo, JUnit XML for
// CI, and the comparison table of `lidarloop compare` (markdown for people, CSV for spreadsheets).
// Every writer throws InputError naming the path when the file cannot be written.
#include <optional>
#include <string>
#include <vector>

#include "scoring/scorer.hpp"

namespace lidarloop {

// Writes `text` to `path` as it is; InputError naming the path when it cannot.
void write_text_file(const std::string& path, const std::string& text);
// The whole file, or nothing when it cannot be read.
std::optional<std::string> read_text_file(const std::string& path);
// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& s);

// metrics.json: every Metrics field (thresholds as an object, unset ones null; undefined values such
// as the RMSE of zero frames are null too, since JSON has no NaN); `reference` null without one.
std::string metrics_json(const Metrics& metrics);
void write_metrics_json(const std::string& path, const Metrics& metrics);

// errors.csv: one line per scored estimate: time, the errors (heading in degrees: this file is read
// by people and plotting scripts), both poses, the estimate's status, latency and standard deviations
// (map axes), then (scoring/scorer.hpp's conventions) the lateral and longitudinal standard deviations in
// the truth's frame, the NEES per axis (nan without a variance), the protection bounds (nan when not
// given), lost, misleading and awaiting_alert (0 or 1; scoring/scorer.hpp's integrity convention).
void write_errors_csv(const std::string& path, const ScoredRun& run, const std::vector<EstimateRecord>& estimates);

// TUM trajectory for evo: `t x y z qx qy qz qw`, t in seconds, z = 0, the yaw as a rotation about z
// (ros2::yaw_quaternion), every number exact (logs/tum_file.hpp), so `lidarloop score` reads back
// the poses scored here.
std::string tum_line(int64_t stamp_ns, const Pose2d& pose);
void write_tum(const std::string& path, const std::vector<TruthPose>& poses);
void write_tum(const std::string& path, const std::vector<EstimateRecord>& estimates);

// JUnit XML: one testsuite per scenario (in first-seen order), one testcase per method, with a
// <failure> when the method failed its thresholds.
std::string junit_xml(const std::vector<Metrics>& runs);
void write_junit(const std::string& path, const std::vector<Metrics>& runs);

// Like the paper's Table III: method | lateral RMSE m | longitudinal RMSE m | heading RMSE deg |
// max error m | latency p50 ms | coverage | pass. A scenario column is added when the runs span several.
std::string comparison_markdown(const std::vector<Metrics>& runs);
// The accuracy against the truth and against the reference side by side, for the runs that have a
// reference (Metrics::reference): method | lateral RMSE m: truth | reference | longitudinal ... |
// heading ... | max error m: truth | reference; a scenario column when the runs span several. Empty
// when no run has a reference.
std::string reference_markdown(const std::vector<Metrics>& runs);
// The same columns as comparison_markdown (and always the scenario) with full precision.
void write_comparison_csv(const std::string& path, const std::vector<Metrics>& runs);

// For people: how much of the curb the traffic hid over the run and in its worst scan, e.g.
// "the traffic hid 12.3% of the curb samples in range (worst scan 45.6%)".
std::string curb_occlusion_text(const Metrics& m);
// For people: the covariance's consistency, e.g. "mean NEES lateral 1.02, longitudinal 2.80, heading
// 0.90 (1 when honest); beyond 3 sigma 1.20% of 540 frames"; n/a where an axis has no variance.
std::string consistency_text(const Metrics& m);
// For people: "misleading 0 of 540 frames with bounds (0.00%), available 93.1% (alert limits ...)".
std::string integrity_text(const Metrics& m);
// For people: "kidnap at 10.00 s: converged after 1.50 s, lost raised after 0.40 s, cleared after 2.00 s".
std::string recovery_text(const EventRecovery& r);
// The three above as a command's summary lines ("nees       ...", "integrity  ...", one "recovery   ..."
// per event), each after "label: " when a label is given (a method, in a comparison).
std::string integrity_lines(const Metrics& m, const std::string& label = "");
// For people: the run's reference and the accuracy against it, e.g. "rtk (0.030 m per axis, 0.10 deg,
// correlation 30 s): against it lateral RMSE 0.190 m, ...; itself off the truth by 0.031 m lateral, ...".
std::string reference_text(const Metrics& m);
// The above as a command's summary line ("reference  ..."), after "label: " when a label is given;
// empty without a reference, so a run without one prints what it always did.
std::string reference_lines(const Metrics& m, const std::string& label = "");
// The localizer's time per scan: p50, p99 and max, and the first scan's (with the start-up) apart.
std::string latency_text(const Metrics& m);

}  // namespace lidarloop
