#pragma once
// Every parameter of the localizer in one place, with the paper's defaults (Table I) where it gives
// them, and the YAML section that overrides them (a scenario's `localizer:`). The keys are the field
// names, grouped by module; see the README's localizer section for the list.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/localizer_method.hpp"
#include "common/yaml_reader.hpp"
#include "localizer/aps_matcher.hpp"
#include "localizer/body_roll.hpp"
#include "localizer/curb_detector.hpp"
#include "localizer/curb_features.hpp"
#include "localizer/curb_match_covariance.hpp"
#include "localizer/driving_corridor.hpp"
#include "localizer/fmt_matcher.hpp"
#include "localizer/gicp_matcher.hpp"
#include "localizer/gps_jitter.hpp"
#include "localizer/gps_step_detector.hpp"
#include "localizer/intensity_calibration.hpp"
#include "localizer/lost_detector.hpp"
#include "localizer/obstacle_rejection.hpp"
#include "localizer/pose_filter.hpp"
#include "localizer/probabilistic_icp.hpp"
#include "localizer/protection_bound.hpp"
#include "localizer/relocalization.hpp"

namespace lidarloop {

bool uses_curbs(LocalizerMethod m);
bool uses_intensity(LocalizerMethod m);
bool removes_obstacles(LocalizerMethod m);

// When the localizer calls its inputs unhealthy, and what it refuses to use.
struct HealthParams {
  double gps_timeout_s = 1.0;     // no fix for this long: "no GPS"
  double can_timeout_s = 0.1;     // no CAN frame for this long: "CAN gap" (the bus runs at 100 Hz)
  int min_scan_points = 1000;     // fewer valid points: treated as an empty scan
  int min_curbs = 15;             // fewer curb features (n_p): no curb observation
  double min_inlier_ratio = 0.5;  // a match explaining fewer of the features is not used
  // Innovation gate of the map-matching observations: chi^2 with 3 (curbs) or 2 (intensity) degrees of
  // freedom at 99.9 %. Past `max_rejections` in a row the filter doubles its position variance with
  // every further rejection, up to max_inflated_sigma_m: if the filter is what went wrong, the gate
  // then opens to the map; a matcher that has run off (tens of metres) stays locked out.
  double gate_curb = 16.27, gate_intensity = 13.82;
  // A GPS fix against the receiver's own variance (not the scaled one): chi^2, 2 dof, 99.9 %.
  double gate_gps = 13.82;
  int max_rejections = 10;
  double max_inflated_sigma_m = 2.0;
};

// What the extrinsic calibration leaves unknown (1 sigma): the LiDAR's true mount differs from the
// nominal one the localizer is given by a fixed draw, which turns and shifts every map match alike, so
// no number of scans averages it out. The estimate's reported covariance carries it on top of the
// filter's (a "consider" term: it does not enter the filter's gains). A target-based end-of-line
// calibration is "within 0.1 degree and 3 mm" (arXiv 2008.10542).
struct MountUncertainty {
  double yaw_sigma_deg = 0.1;
  double translation_sigma_m = 0.003;
  // The mount yaw as a state of the filter (pose_filter.hpp), learnt on the road from the map matches
  // and CAN, with yaw_sigma_deg as its prior; the reported covariance then carries the state's doubt
  // of it instead of the consider term.
  bool learn_yaw = false;
};

struct GpsNoise {
  double min_sigma_m = 0.5;  // floor on the receiver's reported position sigma
  double min_heading_sigma_rad = 0.02;
  // A low-cost receiver's error is mostly a slowly wandering bias (Gauss-Markov, tau of minutes), so
  // fixes 0.1 s apart are far from independent, and a filter that takes each as news is pulled to the
  // bias within seconds wherever the map says little (between paint marks, beside a coach). Two ways
  // to say so:
  // - bias_state (the default): the filter carries the bias as a state (pose_filter.hpp); each fix's
  //   white part is learnt from the receiver's own jitter (gps_jitter.hpp), the rest of its reported
  //   variance is the bias's. Nothing here is set from the scenario suite.
  // - variance_scale (bias_state: false): each fix is white noise of the receiver's variance times this;
  //   10 counts ten fixes as one, a number set on the suite (seeds 5, 7, 8: dynamic_campus longitudinal
  //   RMSE 0.17-0.18 m against 0.19-0.26 m with 1, bus_occlusion's worst error 0.24-0.28 m against 0.68 m).
  double variance_scale = 10.0;
  bool bias_state = true;
  // The bias's correlation time, which no fix tells (the receiver reports only its stationary error).
  // A low-cost receiver's bias wanders over minutes (ionosphere, troposphere, multipath: Groves 2013,
  // ch. 9); one minute is the short end, the cautious one: a filter that thinks the bias forgets sooner
  // trusts what it learnt of it less.
  double bias_tau_s = 60.0;
  double heading_bias_tau_s = 60.0;
  GpsJitterParams jitter;
};

// A localizer that is another program, in the loop instead of a built-in method (`exec:PROGRAM ARGS`;
// external/external_localizer.hpp runs it). The localizer itself never reads these.
struct ExternalLocalizerParams {
  std::vector<std::string> command;  // program and arguments; empty: a built-in method
  // Per scan, from its first byte sent to the answer: at 10 Hz a later answer arrives after the next
  // scan, too late for a car running in real time.
  double deadline_ms = 100;
  double startup_timeout_s = 10;  // for the first scan's answer instead: it starts, loads its map
  double exit_timeout_s = 2;      // to exit after the end of the stream
};

// When, in closed loop, the controller gets a scan's estimate (loop/localizer_loop.hpp). A real car's
// localizer starts on a scan once the scan is complete and its answer reaches the controller when it
// is done, a queue's worth later if it fell behind; the controller carries it to the present by
// odometry. The localizer itself never reads these.
enum class LatencyModel {
  automatic,  // measured for an exec: program, one scan period for a built-in method
  one_scan,   // each estimate one scan period after its scan: the built-in loop's pipeline
  measured,   // after the time the localizer took on the scan (wall clock: not repeatable byte for byte)
  fixed,      // after fixed_ms per scan, as if the localizer always took that long (repeatable)
};
struct LatencyParams {
  LatencyModel model = LatencyModel::automatic;
  double fixed_ms = 0;
};
// "one_scan", "measured" or a number of milliseconds (std::invalid_argument otherwise).
LatencyParams parse_latency(const std::string& text);
std::string latency_text(const LatencyParams& latency);

struct LocalizerParams {
  LocalizerMethod method = LocalizerMethod::proposed;
  ExternalLocalizerParams external;
  LatencyParams latency;
  bool deskew = true;  // beyond the paper: per-point motion compensation from CAN
  // The LiDAR's pose in the vehicle frame (the extrinsic calibration). Not in YAML: it comes with the
  // sensor data (scenario's lidar section, a log's transforms).
  Eigen::Isometry3d lidar_mount = Eigen::Isometry3d::Identity();
  // The GPS antenna in the vehicle frame (the lever arm from the rear axle), as the car's configuration
  // gives it: a fix is the antenna's position, and KF1 estimates the rear axle's. Not in YAML either.
  Eigen::Vector3d gps_antenna = Eigen::Vector3d::Zero();
  uint64_t seed = 1;                    // probabilistic ICP's draws
  double map_window_m = 32;             // curbs of the map within this half size are matched against
  double max_prediction_step_s = 0.01;  // Eq. 19 is integrated in steps no longer than this

  CorridorParams corridor;
  ObstacleParams obstacles;
  CurbDetectorParams curb_detector;
  CurbFeatureParams curb_features;
  ProbabilisticIcpParams probabilistic_icp;
  IcpParams icp;  // the icp and icp-obs baselines
  MIcpParams m_icp;
  FmtParams fmt;
  GicpParams gicp;  // the gicp method (beyond the paper): see gicp_matcher.hpp
  IntensityGridParams intensity_grid;
  IntensityCalibrationParams intensity_calibration;  // beyond the paper: see intensity_calibration.hpp
  ApsParams aps;
  // Beyond the paper: APS's window (+-1 m, +-3 m) assumes the prior is already that good. While it is
  // not (the first GPS fix, after an outage), the window grows to this many prior sigmas, up to the
  // maxima (a peak on the window's edge is then refused: the truth may lie beyond).
  double aps_window_sigmas = 3.0;
  // Likewise for the curb matchers' correspondence distance: at least the configured one, widened to
  // this many prior sigmas (up to the maximum) so that a first GPS fix 2-3 m off still converges.
  double icp_window_sigmas = 3.0, icp_max_correspondence_m = 5.0;
  double aps_max_lateral_range_m = 2.0, aps_max_longitudinal_range_m = 8.0;
  // APS's covariance (the spread of Eq. 14's distribution) times this is the observation noise.
  double aps_covariance_scale = 1.0;
  // When the curbs were matched in the same scan, use APS only along the road. Across it the curbs
  // are the better witness (section 3.2 searches only +-1 m there for that reason), and the paint
  // that APS sees across a road is periodic: zebra stripes and parallel lane lines let a wrong
  // lateral peak look sharp (seen as 3-6 cm lateral spikes at the crosswalks of dynamic_campus).
  bool aps_longitudinal_only_with_curbs = true;
  // Beyond the paper: APS updates an axis only where its distribution's variance is at most this
  // fraction of a uniform spread over the search window's extent on that axis (1 = no information).
  double aps_max_spread_ratio = 0.5;
  // Beyond the paper: ... and along the road only where its best offset beats the best other peak along
  // it by this much of Eq. 14's log P with the prior (ApsResult::along_margin). Measured over seven campus
  // scenarios (seeds 1-4, intensity and proposed; APS's answer against the truth, with the filter within
  // 0.3 m): below a margin of 6, 17-43 % of the answers were more than 0.5 m off along the road, 12 % at
  // 6-8, 7 % at 8-10, 3-5 % at 10-50, 2.9 % at 50-100, 0.2 % above.
  double aps_min_along_margin = 8.0;
  // In a window grown to the prior's doubt (a cold start, a lost filter) an answer farther than this many
  // prior sigmas along the road from the prior must beat the rest by relocalization.min_aps_margin, as
  // the wide search's places must: there 25-85 % of the answers with margins up to 50 were 0.5 m off or
  // more (a noise spike among dashes, the paint a dash period away), 1 % of those over 100. Nearer, the
  // answer agrees with the GPS, and the paint a period away lies in the prior's tail.
  double aps_grown_within_sigmas = 1.0;
  VehicleModelParams vehicle;
  BodyRollParams body_roll;  // beyond the paper: the scan unrolled from the body (body_roll.hpp)
  PoseFilterParams filter;
  double process_position_without_can_per_s = 2.0;  // m per s of dead reckoning without CAN
  CurbMatchNoise curb_noise;
  GpsNoise gps_noise;
  HealthParams health;
  GpsStepParams gps_steps;
  LostParams lost;
  MountUncertainty mount_uncertainty;
  RelocalizationParams relocalization;
  IntegrityParams integrity;
};

// A method as scenarios and the command line give it: a built-in name, or "exec:PROGRAM ARGS" (words
// split as a shell would, with '...' and "..." quoting and backslash escapes, no expansion). Throws
// std::invalid_argument naming what is wrong.
void set_method(LocalizerParams& params, const std::string& text);
// The method's name for tables and folders: the built-in's, or "exec-" and the program's file name
// (and its first argument's, as in `node localizer.mjs`), in [A-Za-z0-9._-].
std::string method_label(const LocalizerParams& params);
// The same from a method's text (as set_method takes it).
std::string method_label(const std::string& method_text);
// The text set_method takes back: the built-in's name, or "exec:" and the words, quoted where needed.
std::string method_text(const LocalizerParams& params);
// The words of a command line (see set_method).
std::vector<std::string> split_command_line(const std::string& text);

// Overrides `params` from a `localizer:` mapping (the key `method` included). Unknown keys, wrong
// types and out-of-range values are InputErrors naming the file, line and column.
void read_localizer_params(const YamlReader& y, const YAML::Node& node, LocalizerParams& params);

}  // namespace lidarloop
