#pragma once
// The localizer as a car runs it: messages in, estimates out. Feed CAN frames, GPS fixes and LiDAR
// scans in time order; every scan yields an estimate of the pose at the scan's end, with its covariance
// and a health status. The runner, replay, benchmarks and tests all drive this one class.
//
// Per scan (paper sections 2-3, method `proposed`):
//   predict to the scan's end with Eq. 19 from CAN -> de-skew the points with CAN odometry ->
//   driving corridor from the curb map (2.1.1) -> ground plane and obstacles (2.1.2, Eq. 2-3) ->
//   single-frame curbs, minus those next to obstacles, accumulated over frames (Eq. 4-5), beam model
//   (Eq. 6-7) (2.2.1) -> grid S of the ground's intensities (2.2.2, Eq. 8) -> probabilistic ICP
//   against the map (3.1) -> KF2 curb update (x, y, psi) (3.3) -> APS of S against the intensity
//   layer around the updated pose (3.2) -> KF2 intensity update (x, y) (3.3).
// GPS fixes update KF1 as they come. The baselines swap or drop the matching steps (LocalizerMethod);
// `gicp` replaces them all by Generalized-ICP of the de-skewed scan against the map's point-cloud layer
// (gicp_matcher.hpp), fused as the curb observation is (KF2 x, y, psi, the same chi^2 gate).
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"
#include "common/map_observation.hpp"
#include "common/point_cloud.hpp"
#include "common/vehicle_messages.hpp"
#include "localizer/curb_features.hpp"
#include "localizer/deskew.hpp"
#include "localizer/gicp_matcher.hpp"
#include "localizer/gps_step_detector.hpp"
#include "localizer/hd_map.hpp"
#include "localizer/innovation_scale.hpp"
#include "localizer/intensity_accumulator.hpp"
#include "localizer/intensity_calibration.hpp"
#include "localizer/localizer_params.hpp"
#include "localizer/lost_detector.hpp"
#include "localizer/relocalization.hpp"

namespace lidarloop {

// What is wrong, as bits: an estimate with none set is "ok".
enum HealthFlag : uint32_t {
  kNotInitialized = 1u << 0,     // no GPS fix yet: there is no pose to report
  kCanGap = 1u << 1,             // no CAN for can_timeout: prediction holds the last speed and steering
  kNoGps = 1u << 2,              // no fix for gps_timeout
  kInvalidPoints = 1u << 3,      // the scan had NaN or infinite points (dropped)
  kEmptyScan = 1u << 4,          // too few valid points to match
  kNoCorridor = 1u << 5,         // no corridor around the pose (off the map?): all points used
  kNoGroundPlane = 1u << 6,      // no plane fit: no obstacle removal this scan
  kFewCurbs = 1u << 7,           // too few curb features: no curb observation (occluded curbs, open area)
  kCurbMatchRejected = 1u << 8,  // the curb match disagreed with the filter or explained too few curbs
  kNoIntensityMatch = 1u << 9,   // APS had too few usable cells (off the intensity map, road hidden)
  kIntensityMatchRejected = 1u << 10,
  kIntensityAmbiguous = 1u << 11,  // APS's distribution was as wide as its window on every axis it may update
  kNoPointMatch = 1u << 12,        // gicp: no point-cloud layer, too few map or scan points to register
  kPointMatchRejected = 1u << 13,  // gicp: not converged, too few scan points matched, or the gate refused it
  // The pose is not to be trusted: the filter has not converged since a cold start, or the observations
  // stopped agreeing with it. The localizer is relocalizing (a wide search) until they agree again.
  kLost = 1u << 14,
  // A GPS fix stepped away from the receiver's usual level and the map sided with the filter: the fixes
  // are not used until they step back (a multipath jump ends).
  kGpsRejected = 1u << 15,
};
constexpr int kHealthFlagCount = 16;
// "ok", or the set flags as words: "no GPS, few curbs".
std::string describe_health(uint32_t flags);

// Wall time spent per stage of one scan, ms (zero for stages the method skips).
enum class Stage {
  deskew,
  corridor,
  obstacles,
  curb_detection,
  curb_features,
  curb_matching,
  intensity_matching,
  point_matching,  // gicp: the local target (when it is cut anew) and the registration
  fusion
};
constexpr int kStageCount = 9;
const char* stage_name(Stage s);

// The LiDAR's mount yaw as the filter has learnt it (MountUncertainty::learn_yaw): the true mount's
// against the nominal one, rad.
struct MountYawEstimate {
  double yaw_rad = 0, sigma_rad = 0;
};

struct LocalizerEstimate {
  int64_t stamp_ns = 0;                                      // the pose's time: the scan's last firing
  Pose2d pose;                                               // rear axle, local frame of the map
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // x, y, psi
  uint32_t health = kNotInitialized;

  // Diagnostics of this scan.
  size_t points = 0, dropped_points = 0, corridor_points = 0, obstacle_points = 0;
  size_t curbs_detected = 0, curb_features = 0;
  std::optional<Pose2d> curb_observation;
  double curb_inlier_ratio = 0;
  std::optional<Eigen::Vector2d> intensity_observation;
  int intensity_cells = 0;
  std::optional<Pose2d> point_observation;  // gicp: where the registration put the car (even if refused)
  double point_fitness = 0;                 // gicp: fraction of the downsampled scan's points matched
  std::array<double, kStageCount> stage_ms{};
  double total_ms = 0;
  bool wide_search = false;  // this scan ran (a share of) a relocalization's wide search

  // Integrity: the lateral and longitudinal error (m, in the estimate's own vehicle frame) that the
  // estimate exceeds with at most the probability LocalizerParams::integrity states. Infinite while lost.
  double protection_lateral_m = std::numeric_limits<double>::infinity();
  double protection_longitudinal_m = std::numeric_limits<double>::infinity();

  std::optional<MountYawEstimate> mount_yaw;  // when learnt
  // What the filter took from the map this scan: the curbs' (or gicp's) pose, APS's position.
  std::optional<MapObservation> fused_pose, fused_intensity;

  bool ok() const { return health == 0; }
  bool lost() const { return (health & kLost) != 0; }
};

// The features of the last scan, for pictures (the paper's Fig. 14); vehicle frame.
struct ScanFeatures {
  std::vector<Eigen::Vector2d> curbs, obstacles;
};

// What drives Eq. 19 in a CAN frame: the rear axle centre's speed (mean of the rear wheels, m/s) and
// the front wheel angle (steering wheel angle over the steering ratio, rad).
struct CanMotion {
  double speed = 0, steer = 0;
};
CanMotion can_motion(const CanFrame& f, const VehicleModelParams& vehicle);

class Localizer {
 public:
  // `map` must outlive the localizer (its intensity layer loads tiles as the car moves).
  Localizer(HdMap& map, const LocalizerParams& params);

  void on_can(const CanFrame& frame);
  void on_gps(const GpsFix& fix);
  LocalizerEstimate on_scan(const PointCloud& cloud);

  // A known start instead of waiting for the first GPS fix.
  void initialize(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& covariance);
  bool initialized() const { return filter_.has_value(); }
  // A kidnap, for testing relocalization: the filter's pose moves by `offset` (x forward, y left in its
  // own vehicle frame, yaw added) and keeps its covariance, so it does not know. No-op before
  // initialisation.
  void displace(const Pose2d& offset);
  // The filter's current pose (predicted to the latest message); nullopt before initialisation.
  std::optional<Pose2d> pose() const;

  const LocalizerParams& params() const { return params_; }
  const ScanFeatures& last_features() const { return features_; }

 private:
  // A pose observation of KF2 (curbs, or gicp's registration): the pose it puts the car at, and how well
  // it pins it down.
  struct PoseObservation {
    Pose2d pose;
    Eigen::Matrix3d covariance;
  };

  void predict_to(int64_t t_ns);
  uint32_t input_health(int64_t t_ns) const;
  // The stages of on_scan that use the localizer's state (the others are free functions in
  // localizer.cpp); each records its diagnostics, health bits and time in `e`.
  void process_scan(const PointCloud& cloud, LocalizerEstimate& e);
  Pose2d motion_since_previous_scan();
  std::vector<Eigen::Vector2d> curb_features(std::vector<Eigen::Vector2d> curbs,
                                             const std::vector<Eigen::Vector2d>& obstacles, const Pose2d& motion,
                                             LocalizerEstimate& e);
  std::optional<PoseObservation> match_curbs(const std::vector<Eigen::Vector2d>& features, LocalizerEstimate& e);
  std::optional<Pose2d> curb_correction(const std::vector<Eigen::Vector2d>& features_world, const MapIndex& local_map,
                                        const Pose2d& prior);
  void fuse_curbs(const PoseObservation& z, LocalizerEstimate& e);
  // The KF2 update (x, y, psi) behind the chi^2 gate; false if the gate refused it.
  // `doubt`: added to the filter's covariance for this observation, if the gate lets it through.
  bool fuse_pose(const PoseObservation& z, int& rejections, LocalizerEstimate& e,
                 const Eigen::Matrix3d& doubt = Eigen::Matrix3d::Zero());
  std::optional<PoseObservation> match_points(const ScanPoints& points, LocalizerEstimate& e);
  std::optional<ApsResult> match_intensity(IntensityGrid& S, LocalizerEstimate& e);
  ApsParams aps_window(const Pose2d& prior) const;
  // S's redundancy and turning (IntensityGrid) say how far to widen APS's claim, and which scale applies.
  void fuse_intensity(const ApsResult& aps, const IntensityGrid& grid, LocalizerEstimate& e);
  bool pose_known_to_calibrate() const;
  void calibrate_lasers_to_each_other(const ScanPoints& points, const std::vector<size_t>& ground);
  void calibrate_lasers_to_the_map(const ScanPoints& points, const std::vector<size_t>& ground);
  void match_and_fuse(IntensityGrid* S, LocalizerEstimate& e);
  // While lost: a share of the wide search (relocalization) with this scan's S and curbs; the filter
  // moves to what it finds.
  void relocalize(IntensityGrid* S, LocalizerEstimate& e);
  void start_relocalization();
  void move_to(const Relocation& found);
  // The search admits the doubt that made the filter lost: its window grows to cover where the refused
  // observations put the car (the filter's own spread is left as it was).
  void widen_to(const std::deque<Disagreement>& refused);
  void disagree(const Eigen::Vector2d& innovation, bool gps = false);
  void judge_gps_jump(const Pose2d& placed);
  // A map match the filter took (updated from `prior`), pinning down these axes of the car.
  void agree(const Pose2d& prior, const Eigen::Vector2d& innovation, bool along, bool across);
  // Whether APS's innovation along the road, informative by itself, may update the filter, its window on
  // that axis `grown` to the prior's spread (see the .cpp).
  bool confirmed_along(bool informative, bool grown, double innovation_along);
  double position_sigma() const;  // the filter's, largest axis
  void report_pose(LocalizerEstimate& e);
  // The chi^2 gate, with the filter's doubt growing after max_rejections in a row (see
  // HealthParams); true: use the observation.
  bool gate(double mahalanobis_sq, double threshold, int& rejections);
  GpsErrorModel gps_error_model(const Eigen::Vector3d& reported) const;

  HdMap& map_;
  LocalizerParams params_;
  LocalFrame frame_;
  std::mt19937_64 rng_;

  MotionPredictor predictor_;
  Pose2d odometry_;  // dead reckoning from CAN alone: what the curb accumulation moves frames by
  std::optional<PoseFilter> filter_;
  int64_t time_ns_ = 0;           // the time odometry and filter are predicted to
  double speed_ = 0, steer_ = 0;  // the last CAN frame's (held until the next)
  std::optional<int64_t> last_can_ns_, last_gps_ns_;

  CurbAccumulator accumulator_;
  IntensityAccumulator intensity_accumulator_;  // the ground of the last scans, for S
  std::optional<Pose2d> previous_scan_odometry_;
  int curb_rejections_ = 0, intensity_rejections_ = 0, point_rejections_ = 0;
  GicpTarget gicp_target_;
  // The last registration's height, roll and pitch: the next one's starting guess (the filter has only
  // x, y, psi).
  Eigen::Isometry3d last_registration_ = Eigen::Isometry3d::Identity();
  IntensityCalibration intensity_calibration_;
  ScanFeatures features_;

  // APS's noise as its innovations show it, apart on straights and in bends (IntensityGrid::turning):
  // in a bend S is one scan, de-skewed through the turn, and its curved paint ties the position along
  // the road to the heading; there APS erred 2.5 times as far as on the straights while its spread
  // claimed less (gps_degraded at b9e57ab: RMS longitudinal error 0.31 m against 0.125 m).
  InnovationScale aps_scale_straight_, aps_scale_turning_;
  // A grown window's APS innovation along the road, held back until the next scan's agrees with it.
  std::optional<double> held_along_;
  LostDetector lost_;
  GpsStepDetector gps_steps_;
  GpsJitter gps_jitter_;
  // The previous fix (rear axle, local frame; heading) and the odometry then: the jitter's pair.
  struct GpsPair {
    int64_t stamp_ns;
    Eigen::Vector3d z;
    Pose2d odometry;
  };
  std::optional<GpsPair> previous_fix_;
  Relocalizer relocalizer_;
  BodyRoll body_roll_;                                       // the body's roll from CAN, to unroll the scans
  Eigen::Vector3d search_sigmas_ = Eigen::Vector3d::Zero();  // longitudinal, lateral (m), yaw (rad)
  bool gps_stepped_ = false;  // the GPS's disagreement that made the localizer lost was a step
  // Set while the GPS is rejected (kGpsRejected): the innovation level it had before it jumped.
  std::optional<Eigen::Vector2d> gps_fault_level_;
  // The relocalization's hypotheses: the filter as it was when it became lost (none after a cold start),
  // and the newest fix (rear axle, the filter's heading; the receiver's own variances, or with the bias a
  // state, less the bias and with its doubt).
  // Each is kept with the dead-reckoning pose of its time, and carried to the present by odometry
  // (carried()) before it is used: the car drives on (10 m in a second) while a search runs.
  struct PoseBelief {
    Pose2d pose;
    Eigen::Matrix3d covariance;
    Pose2d odometry;
  };
  PoseBelief carried(const PoseBelief& belief) const;
  // The filter's parameters, with the mount yaw's prior when it is learnt.
  PoseFilterParams filter_params() const;
  std::optional<PoseBelief> trusted_, last_fix_;
  bool lost_by_gps_ = false;                      // the GPS was among the disagreements that made the filter lost
  std::optional<Eigen::Vector2d> last_gps_step_;  // the last step of the fixes from their level
};

}  // namespace lidarloop
