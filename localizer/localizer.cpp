#include "localizer/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Dense>

#include "common/units.hpp"
#include "localizer/aps_matcher.hpp"
#include "localizer/curb_detector.hpp"
#include "localizer/curb_match_covariance.hpp"
#include "localizer/deskew.hpp"
#include "localizer/driving_corridor.hpp"
#include "localizer/obstacle_rejection.hpp"
#include "localizer/stage_timer.hpp"

namespace lidarloop {
namespace {

// The upper median (the values are reordered).
double median_of(std::vector<double>& values) {
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  return values[values.size() / 2];
}

// Before the first fix there is no pose: the estimate says so with this (m^2, rad^2) on the diagonal.
constexpr double kUnknownVariance = 1e6;
// APS's window is rounded down to whole steps; a window meant to be a whole number of steps must not
// lose its last one to rounding.
constexpr double kWholeStepTolerance = 1e-9;

Eigen::Vector2d xy(const Pose2d& p) { return {p.x, p.y}; }

double& stage_ms(LocalizerEstimate& e, Stage s) { return e.stage_ms[size_t(s)]; }

// The scan in the vehicle frame at `reference_ns` after its stamp, de-skewed with CAN's motion over
// the scan unless that is switched off, and turned back by the body's roll.
ScanPoints vehicle_frame_points(const PointCloud& cloud, const LocalizerParams& params, const ScanMotion& motion,
                                int64_t reference_ns, double body_roll, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::deskew));
  ScanPoints points = params.deskew ? deskew(cloud, params.lidar_mount, motion, reference_ns)
                                    : to_vehicle_frame(cloud, params.lidar_mount);
  unroll(points.xyz, body_roll, params.body_roll.pivot_height_m);
  e.points = points.size();
  e.dropped_points = points.dropped;
  if (points.dropped > 0) e.health |= kInvalidPoints;
  return points;
}

// 2.1.1: the points inside the driving corridor around `prior` (indices into `points`); all of them
// when there is no corridor (off the map).
std::vector<size_t> corridor_points(const ScanPoints& points, const CurbLayer& curbs, const Pose2d& prior,
                                    const CorridorParams& params, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::corridor));
  const double half = 0.5 * std::max(params.width_cells, params.height_cells) * params.cell_m;  // the grid's reach
  const DrivingCorridor corridor = extract_driving_corridor(curbs.window(xy(prior), half), prior, params);
  const bool have_corridor = !corridor.mask.empty();
  if (!have_corridor) e.health |= kNoCorridor;
  std::vector<size_t> inside;
  if (have_corridor) {
    inside = corridor.inside(points.xyz);
  } else {
    inside.resize(points.size());
    std::iota(inside.begin(), inside.end(), size_t{0});
  }
  e.corridor_points = inside.size();
  return inside;
}

// 2.1.2: the ground plane through the corridor's points (Eq. 2) and the obstacles above it (Eq. 3),
// appended to `obstacles` (vehicle frame). Returns the road surface for S (indices into `points`):
// the ground points close to the plane (see IntensityGridParams::max_height).
std::vector<size_t> split_ground_and_obstacles(const ScanPoints& points, const std::vector<size_t>& corridor,
                                               const LocalizerParams& params, std::vector<Eigen::Vector2d>& obstacles,
                                               std::optional<Plane>& plane, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::obstacles));
  std::vector<Eigen::Vector3d> corridor_xyz;
  corridor_xyz.reserve(corridor.size());
  for (size_t i : corridor) corridor_xyz.push_back(points.xyz[i]);
  const ObstacleSplit split = reject_obstacles(corridor_xyz, params.obstacles);
  if (!split.plane_ok) e.health |= kNoGroundPlane;
  if (split.plane_ok) plane = split.plane;
  std::vector<size_t> ground;
  ground.reserve(split.ground_index.size());
  const PlaneLeveller level(split.plane);
  for (size_t k : split.ground_index)  // Eq. 3's distance_to_plane
    if (!split.plane_ok || std::abs(level.height(corridor_xyz[k])) <= params.intensity_grid.max_height)
      ground.push_back(corridor[k]);
  for (const auto& o : split.obstacles) obstacles.push_back(o.head<2>());
  e.obstacle_points = obstacles.size();
  return ground;
}

// 2.2.1, single frame: the curbs along the scan's rings (vehicle frame). Beyond the paper: with a
// ground plane (2.1.2) the detector reads heights above it, so a car rolled on a crowned road or
// pitched on a grade sees its curbs as a level one would.
std::vector<Eigen::Vector2d> detect_scan_curbs(const ScanPoints& points, const std::optional<Plane>& plane,
                                               const CurbDetectorParams& params, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::curb_detection));
  std::vector<Eigen::Vector2d> curbs = detect_curbs(points.xyz, points.ring, params, plane);
  e.curbs_detected = curbs.size();
  return curbs;
}

// 2.2.2: grid S of the road surface's intensities around the vehicle (Eq. 8), placed at `pose`, from
// this scan's ground away from its obstacles and the frames before it (intensity_accumulator.hpp), each
// laser's reading first put on the map's scale (beyond the paper: intensity_calibration.hpp).
IntensityGrid intensity_grid(const ScanPoints& points, const std::vector<size_t>& ground,
                             const std::vector<Eigen::Vector2d>& obstacles, const Pose2d& pose, const Pose2d& motion,
                             const IntensityGridParams& params, int min_count, const IntensityCalibration& calibration,
                             IntensityAccumulator& accumulator, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::intensity_matching));
  const std::vector<char> near_obstacle =
      in_marked_cells(params, cells_near_obstacles(obstacles, params), points.xyz, ground);
  std::vector<Eigen::Vector2d> ground_xy;
  std::vector<double> intensities;
  ground_xy.reserve(ground.size());
  intensities.reserve(ground.size());
  for (size_t k = 0; k < ground.size(); ++k) {
    if (near_obstacle[k]) continue;
    const size_t i = ground[k];
    ground_xy.push_back(points.xyz[i].head<2>());
    intensities.push_back(calibration.correct(points.ring[i], points.intensity[i]));
  }
  accumulator.add(std::move(ground_xy), std::move(intensities), motion);
  return accumulator.grid(pose, params, min_count);
}

// The map's curbs around `centre` in a small KD-tree of their own: the matchers' thousands of
// nearest-neighbour queries are then cheaper than in the whole map's tree.
struct LocalCurbs {
  MapIndex index;
  std::vector<Eigen::Vector2d> tangents;  // of index.points(), in their order
};

LocalCurbs local_curbs(const CurbLayer& curbs, const Eigen::Vector2d& centre, double half_extent) {
  std::vector<Eigen::Vector2d> points, tangents;
  for (size_t i : curbs.window_indices(centre, half_extent)) {
    points.push_back(curbs.points()[i]);
    tangents.push_back(curbs.tangents()[i]);
  }
  return {MapIndex(std::move(points)), std::move(tangents)};
}

// Each axis's sigma of `covariance` in `pose`'s vehicle frame (longitudinal, lateral, yaw).
Eigen::Vector3d vehicle_sigmas(const Eigen::Matrix3d& covariance, const Pose2d& pose) {
  const Eigen::Vector2d forward(std::cos(pose.yaw), std::sin(pose.yaw)), left(-forward.y(), forward.x());
  const Eigen::Matrix2d P = covariance.topLeftCorner<2, 2>();
  return {std::sqrt(forward.dot(P * forward)), std::sqrt(left.dot(P * left)), std::sqrt(covariance(2, 2))};
}

}  // namespace

CanMotion can_motion(const CanFrame& f, const VehicleModelParams& vehicle) {
  return {0.5 * (f.wheel_speed_mps[2] + f.wheel_speed_mps[3]),  // rear axle centre
          f.steering_wheel_angle_rad / vehicle.steering_ratio};
}

std::string describe_health(uint32_t flags) {
  static const std::array<const char*, kHealthFlagCount> names = {"not initialised",
                                                                  "CAN gap",
                                                                  "no GPS",
                                                                  "invalid points",
                                                                  "empty scan",
                                                                  "no corridor",
                                                                  "no ground plane",
                                                                  "few curbs",
                                                                  "curb match rejected",
                                                                  "no intensity match",
                                                                  "intensity match rejected",
                                                                  "intensity match ambiguous",
                                                                  "no point match",
                                                                  "point match rejected",
                                                                  "lost",
                                                                  "GPS rejected"};
  if (flags == 0) return "ok";
  std::string out;
  for (int i = 0; i < kHealthFlagCount; ++i)
    if (flags & (1u << i)) out += (out.empty() ? "" : ", ") + std::string(names[size_t(i)]);
  return out;
}

const char* stage_name(Stage s) {
  static const std::array<const char*, kStageCount> names = {
      "deskew",        "corridor",           "obstacles",      "curb_detection", "curb_features",
      "curb_matching", "intensity_matching", "point_matching", "fusion"};
  return names[size_t(s)];
}

Localizer::Localizer(HdMap& map, const LocalizerParams& params)
    : map_(map),
      params_(params),
      frame_(map.curbs.map().origin),
      rng_(params.seed),
      predictor_(params.vehicle),
      accumulator_(params.curb_features.frames),
      intensity_accumulator_(params.intensity_grid.frames, params.intensity_grid.max_turn_deg / kDegPerRad),
      intensity_calibration_(params.intensity_calibration),
      lost_(params.lost),
      gps_steps_(params.gps_steps),
      gps_jitter_(params.gps_noise.jitter),
      relocalizer_(params.relocalization),
      body_roll_(params.body_roll) {}

PoseFilterParams Localizer::filter_params() const {
  PoseFilterParams p = params_.filter;
  if (params_.mount_uncertainty.learn_yaw) p.mount_yaw_sigma_rad = params_.mount_uncertainty.yaw_sigma_deg / kDegPerRad;
  return p;
}

void Localizer::initialize(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& covariance) {
  predict_to(stamp_ns);
  relocalizer_.finish();
  filter_.emplace(pose, covariance, filter_params());
}

void Localizer::displace(const Pose2d& offset) {
  if (!filter_) return;
  filter_->displace_to(filter_->pose().compose(offset));
}

std::optional<Pose2d> Localizer::pose() const {
  if (!filter_) return std::nullopt;
  return filter_->car_pose();
}

void Localizer::predict_to(int64_t t_ns) {
  if (t_ns <= time_ns_) return;
  const Pose2d before = odometry_;
  const double dt = double(t_ns - time_ns_) / kNsPerS;
  odometry_ = predictor_.advance(odometry_, speed_, steer_, t_ns - time_ns_, params_.max_prediction_step_s);
  body_roll_.step(predictor_.lateral_acceleration(), dt);
  time_ns_ = t_ns;
  if (!filter_) return;
  // The filter moves by the odometry's increment in its own frame.
  const Pose2d step = relative(before, odometry_);
  filter_->predict(filter_->car_pose().compose(step), std::hypot(step.x, step.y), dt);
  const bool can_stale = !last_can_ns_ || double(t_ns - *last_can_ns_) / kNsPerS > params_.health.can_timeout_s;
  if (can_stale) {
    const double q = params_.process_position_without_can_per_s;
    filter_->inflate(Eigen::Vector3d(q * q * dt, q * q * dt, 0).asDiagonal());
  }
}

void Localizer::on_can(const CanFrame& f) {
  if (last_can_ns_ && f.stamp_ns < *last_can_ns_) return;  // out of order: stale news
  const CanMotion m = can_motion(f, params_.vehicle);
  if (!std::isfinite(m.speed) || !std::isfinite(m.steer)) return;
  predict_to(f.stamp_ns);  // with the previous frame's values, held until now
  speed_ = m.speed;
  steer_ = m.steer;
  last_can_ns_ = f.stamp_ns;
}

// The receiver's variance, times `scale`, as white noise: no bias state.
static GpsErrorModel white_gps(const Eigen::Vector3d& reported, double scale) {
  GpsErrorModel m;
  m.white_variance = reported * scale;
  return m;
}

void Localizer::on_gps(const GpsFix& fix) {
  if (fix.status == GpsStatus::no_fix) return;
  if (!std::isfinite(fix.lat_deg) || !std::isfinite(fix.lon_deg) || !std::isfinite(fix.heading_rad)) return;
  predict_to(fix.stamp_ns);
  // The fix is the antenna's; the rear axle is the lever arm behind it, turned by the heading (the
  // filter's when it has one: the receiver's heading is the worse by far).
  const double heading = filter_ ? filter_->car_pose().yaw : fix.heading_rad;
  const Eigen::Vector2d p =
      frame_.to_local(fix.lat_deg, fix.lon_deg) - Eigen::Rotation2Dd(heading) * params_.gps_antenna.head<2>();
  const GpsNoise& n = params_.gps_noise;
  auto variance = [&](double reported, double floor) {
    return std::isfinite(reported) ? std::max(reported, floor * floor) : floor * floor;
  };
  // The receiver's own word: the stationary variance of its error.
  const Eigen::Vector3d reported(variance(fix.position_covariance[0], n.min_sigma_m),
                                 variance(fix.position_covariance[4], n.min_sigma_m),
                                 variance(fix.heading_variance, n.min_heading_sigma_rad));
  const Eigen::Matrix3d R = reported.asDiagonal();
  const Eigen::Vector3d z(p.x(), p.y(), wrap_angle(fix.heading_rad));
  const std::optional<GpsPair> previous = previous_fix_;
  previous_fix_ = GpsPair{fix.stamp_ns, z, odometry_};
  last_gps_ns_ = fix.stamp_ns;
  if (!filter_) {
    // A cold start: lost until the map has pinned the pose down.
    // One fix is as good as the receiver says; a scale is for the correlation between many.
    filter_ = PoseFilter::from_gps_fix(z, gps_error_model(reported), filter_params());
    last_fix_ = {filter_->pose(), R, odometry_};
    lost_.start_search();
    trusted_.reset();
    // The map's intensity tiles where the first scans will read them (S's reach and the wide search's),
    // read now rather than inside the first scan's budget, as a map loader reads around the first fix.
    if (uses_intensity(params_.method)) {
      const IntensityGridParams& g = params_.intensity_grid;
      const RelocalizationParams& r = params_.relocalization;
      map_.intensity.preload(p, 0.5 * std::max(g.width_cells, g.height_cells) * g.cell_m +
                                    std::max(r.max_longitudinal_m, r.max_lateral_m));
    }
    return;
  }
  const Eigen::Vector2d innovation = p - xy(filter_->pose());
  const bool stepped = gps_steps_.step(fix.stamp_ns, innovation);
  if (n.bias_state && !gps_fault_level_ && previous &&
      double(fix.stamp_ns - previous->stamp_ns) / kNsPerS <= params_.health.gps_timeout_s) {
    // The change since the previous fix less the car's motion by odometry (turned into the local frame
    // by the filter's heading): two fixes' white noise.
    const Pose2d moved = relative(previous->odometry, odometry_);
    const Eigen::Vector2d travelled = Eigen::Rotation2Dd(filter_->car_pose().yaw) * Eigen::Vector2d(moved.x, moved.y);
    gps_jitter_.add(Eigen::Vector3d(z.x() - previous->z.x() - travelled.x(), z.y() - previous->z.y() - travelled.y(),
                                    wrap_angle(z.z() - previous->z.z() - moved.yaw)));
  }
  const GpsErrorModel own = gps_error_model(reported);
  if (filter_->has_gps_bias()) {
    // Where the fix puts the car once its learnt bias is taken off (none without bias_state), as sure
    // as that bias is known.
    const Eigen::Vector3d bias = filter_->gps_bias();
    last_fix_ = {Pose2d{p.x() - bias.x(), p.y() - bias.y(), filter_->pose().yaw},
                 filter_->gps_bias_covariance() + Eigen::Matrix3d(own.white_variance.asDiagonal()), odometry_};
  } else {
    last_fix_ = {Pose2d{p.x(), p.y(), filter_->pose().yaw}, R, odometry_};
  }
  const double sigma = gps_steps_.noise_sigma_m();
  if (gps_fault_level_) {
    // Rejected until the jump ends: a fix that steps back to the level it had before.
    if (stepped && (innovation - *gps_fault_level_).squaredNorm() / (sigma * sigma) <= params_.gps_steps.step_gate) {
      gps_fault_level_.reset();
      gps_steps_.restart();
    }
    return;
  }
  // With the bias a state: which part of the error is white is not known before the jitter is.
  if (n.bias_state && !gps_jitter_.calibrated()) return;
  const GpsErrorModel model = n.bias_state ? own : white_gps(reported, n.variance_scale);
  if (lost_.lost()) {
    // Lost: the filter itself moves, so steps say nothing new; only the fixes that stepped before (the
    // GPS may be what jumped) wait for the map's verdict.
    if (!(gps_stepped_ && stepped)) filter_->update_gps(z, model);  // KF1
    return;
  }
  // The fix against the filter's pose and bias (with the receiver's own variance, not the scaled one),
  // or a step.
  const Eigen::Vector2d nu = filter_->gps_innovation(z).head<2>();
  const Eigen::Matrix2d S = filter_->gps_innovation_covariance(own).topLeftCorner<2, 2>();
  if (stepped || nu.dot(S.ldlt().solve(nu)) > params_.health.gate_gps) {
    if (stepped && gps_steps_.level()) {
      gps_stepped_ = true;
      last_gps_step_ = innovation - *gps_steps_.level();
    }
    disagree(innovation, true);
    return;
  }
  filter_->update_gps(z, model);  // KF1
}

// The receiver's error as it reports it (its stationary variance): as white noise, or with bias_state
// split into white noise (as its jitter shows it, never more than the whole) and the bias, the rest.
GpsErrorModel Localizer::gps_error_model(const Eigen::Vector3d& reported) const {
  const GpsNoise& n = params_.gps_noise;
  if (!n.bias_state) return white_gps(reported, 1.0);
  GpsErrorModel m;
  m.white_variance = gps_jitter_.white_variance().cwiseMin(reported);
  m.bias_variance = reported - m.white_variance;
  m.tau_s = Eigen::Vector3d(n.bias_tau_s, n.bias_tau_s, n.heading_bias_tau_s);
  return m;
}

uint32_t Localizer::input_health(int64_t t_ns) const {
  uint32_t flags = 0;
  if (!last_can_ns_ || double(t_ns - *last_can_ns_) / kNsPerS > params_.health.can_timeout_s) flags |= kCanGap;
  if (!last_gps_ns_ || double(t_ns - *last_gps_ns_) / kNsPerS > params_.health.gps_timeout_s) flags |= kNoGps;
  return flags;
}

bool Localizer::gate(double mahalanobis_sq, double threshold, int& rejections) {
  if (std::isfinite(mahalanobis_sq) && mahalanobis_sq <= threshold) {
    rejections = 0;
    return true;
  }
  if (++rejections > params_.health.max_rejections) {
    // The map keeps disagreeing: perhaps the filter, not the map, is wrong. It admits more doubt
    // (its position variance doubles each further rejection, up to a cap), which opens the gate to
    // an observation that stays consistent, while a matcher that has run off stays locked out.
    const double cap = params_.health.max_inflated_sigma_m * params_.health.max_inflated_sigma_m;
    const Eigen::Matrix3d& P = filter_->covariance();
    Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 2; ++i) Q(i, i) = std::clamp(cap - P(i, i), 0.0, P(i, i));
    filter_->inflate(Q);
  }
  return false;
}

LocalizerEstimate Localizer::on_scan(const PointCloud& cloud) {
  LocalizerEstimate e;
  {
    const StageTimer timer(e.total_ms);
    process_scan(cloud, e);
    report_pose(e);
  }
  return e;
}

// The paper's stages in its order; the method (LocalizerMethod) decides which run. Curbs and paint are
// both extracted before either is matched, and APS searches around the pose the curb update left.
void Localizer::process_scan(const PointCloud& cloud, LocalizerEstimate& e) {
  const int64_t scan_ns = scan_duration_ns(cloud);
  e.stamp_ns = std::max(cloud.stamp_ns + scan_ns, time_ns_);
  predict_to(e.stamp_ns);  // Eq. 19 from CAN
  e.health = input_health(e.stamp_ns);
  const Pose2d motion = motion_since_previous_scan();
  features_ = {};
  const LocalizerMethod method = params_.method;
  if (method == LocalizerMethod::gps) return;

  const ScanPoints points =
      vehicle_frame_points(cloud, params_, {speed_, predictor_.yaw_rate()}, scan_ns, body_roll_.roll(), e);
  const bool empty = points.size() < size_t(std::max(params_.health.min_scan_points, 1));
  if (empty) e.health |= kEmptyScan;
  if (empty || !filter_) {
    // Keep the older frames where they are relative to the car.
    accumulator_.add({}, motion);
    intensity_accumulator_.add({}, {}, motion);
    return;
  }

  if (method == LocalizerMethod::gicp) {
    if (const std::optional<PoseObservation> z = match_points(points, e))
      if (!fuse_pose(*z, point_rejections_, e)) e.health |= kPointMatchRejected;
    return;
  }

  std::vector<size_t> ground;  // the road surface, indices into points
  std::optional<Plane> plane;
  if (removes_obstacles(method)) {
    const std::vector<size_t> corridor =
        corridor_points(points, map_.curbs, filter_->pose(), params_.corridor, e);                  // 2.1.1
    ground = split_ground_and_obstacles(points, corridor, params_, features_.obstacles, plane, e);  // 2.1.2
  }
  if (uses_curbs(method))  // 2.2.1
    features_.curbs =
        curb_features(detect_scan_curbs(points, plane, params_.curb_detector, e), features_.obstacles, motion, e);
  std::optional<IntensityGrid> S;
  const bool map_calibration = uses_intensity(method) && pose_known_to_calibrate();
  if (uses_intensity(method) && !map_calibration) {
    const StageTimer timer(stage_ms(e, Stage::intensity_matching));
    calibrate_lasers_to_each_other(points, ground);
  }
  if (uses_intensity(method))  // 2.2.2
    S = intensity_grid(points, ground, features_.obstacles, filter_->pose(), motion, params_.intensity_grid,
                       params_.aps.min_count, intensity_calibration_, intensity_accumulator_, e);

  // While lost the narrow matchers (their windows grown to the filter's doubt) and the GPS still
  // converge the filter as they can (a search may find nothing for long); the search starts afresh
  // whenever they move it, since an unfinished search's places are kept relative to the filter (a
  // place found once waits on, carried by odometry).
  if (lost_.searching()) relocalize(S ? &*S : nullptr, e);
  const Pose2d before = filter_->pose();
  match_and_fuse(S ? &*S : nullptr, e);
  if ((xy(filter_->pose()) - xy(before)).norm() > params_.aps.step_m) relocalizer_.stop();
  if (map_calibration) {
    const StageTimer timer(stage_ms(e, Stage::intensity_matching));
    calibrate_lasers_to_the_map(points, ground);
  }
}

// 3.1-3.3: the curbs, then APS around the pose the curb update left.
void Localizer::match_and_fuse(IntensityGrid* S, LocalizerEstimate& e) {
  if (uses_curbs(params_.method)) {
    const std::optional<PoseObservation> z = match_curbs(features_.curbs, e);  // 3.1
    if (z) fuse_curbs(*z, e);                                                  // 3.3
  }
  if (S) {
    const std::optional<ApsResult> z = match_intensity(*S, e);  // 3.2
    if (z) fuse_intensity(*z, *S, e);                           // 3.3
  }
}

// Beyond the paper: this scan's ground points teach each laser's calibration (intensity_calibration.hpp).
// Until the filter knows where the car is: before S is built, each laser's median ground reading against
// the median of all lasers (no pose needed). Then: after the scan's updates, against the map's
// intensities under the points at the updated pose. One of the two per scan.
bool Localizer::pose_known_to_calibrate() const {
  const Eigen::Matrix3d& P = filter_->covariance();
  const double sigma = params_.intensity_calibration.max_position_sigma_m;
  return P(0, 0) <= sigma * sigma && P(1, 1) <= sigma * sigma;
}

void Localizer::calibrate_lasers_to_each_other(const ScanPoints& points, const std::vector<size_t>& ground) {
  const IntensityCalibrationParams& c = params_.intensity_calibration;
  if (!c.enabled || ground.empty()) return;
  std::vector<std::vector<double>> by_ring(IntensityCalibration::kMaxLasers);
  std::vector<double> all;
  all.reserve(ground.size());
  for (size_t i : ground) {
    all.push_back(points.intensity[i]);
    if (points.ring[i] < by_ring.size()) by_ring[points.ring[i]].push_back(points.intensity[i]);
  }
  const double all_median = median_of(all);
  for (size_t ring = 0; ring < by_ring.size(); ++ring)
    if (by_ring[ring].size() >= size_t(c.min_ring_points))
      intensity_calibration_.add(int(ring), median_of(by_ring[ring]), all_median,
                                 double(by_ring[ring].size()) / double(c.point_stride));
  intensity_calibration_.end_scan();
}

void Localizer::calibrate_lasers_to_the_map(const ScanPoints& points, const std::vector<size_t>& ground) {
  const IntensityCalibrationParams& c = params_.intensity_calibration;
  if (!c.enabled || ground.empty()) return;
  const PoseApplier to_local(filter_->pose());
  for (size_t k = 0; k < ground.size(); k += size_t(c.point_stride)) {
    const std::optional<IntensityCell> cell = map_.intensity.cell(to_local(points.xyz[ground[k]].head<2>()));
    if (cell && int(cell->count) >= c.min_map_count)
      intensity_calibration_.add(points.ring[ground[k]], points.intensity[ground[k]], cell->mean);
  }
  intensity_calibration_.end_scan();
}

Pose2d Localizer::motion_since_previous_scan() {
  const Pose2d motion = previous_scan_odometry_ ? relative(*previous_scan_odometry_, odometry_) : Pose2d{};
  previous_scan_odometry_ = odometry_;
  return motion;
}

// 2.2.1: this scan's curbs, less those at the feet of obstacles (d_o), accumulated over the last
// frames with odometry (Eq. 4-5) and thinned to the contour the beams see (Eq. 6-7).
std::vector<Eigen::Vector2d> Localizer::curb_features(std::vector<Eigen::Vector2d> curbs,
                                                      const std::vector<Eigen::Vector2d>& obstacles,
                                                      const Pose2d& motion, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::curb_features));
  if (removes_obstacles(params_.method))
    curbs = reject_near_obstacles(curbs, obstacles, params_.curb_features.obstacle_distance);
  accumulator_.add(curbs, motion);  // Eq. 4-5
  std::vector<Eigen::Vector2d> features =
      beam_model(accumulator_.curbs(), accumulator_.launch_points(), params_.curb_features);  // Eq. 6-7
  e.curb_features = features.size();
  return features;
}

// 3.1: the pose the curb features put the car at, matched against the map's curbs around the prior,
// with the covariance the match supports; nullopt (and why, in e.health) if there is none to use.
std::optional<Localizer::PoseObservation> Localizer::match_curbs(const std::vector<Eigen::Vector2d>& features,
                                                                 LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::curb_matching));
  if (features.size() < size_t(params_.health.min_curbs)) {
    e.health |= kFewCurbs;
    return std::nullopt;
  }
  const Pose2d prior = filter_->pose();
  std::vector<Eigen::Vector2d> world;
  world.reserve(features.size());
  for (const auto& f : features) world.push_back(vehicle_to_world(prior, f));
  const LocalCurbs local = local_curbs(map_.curbs, xy(prior), params_.map_window_m);
  const std::optional<Pose2d> t = curb_correction(world, local.index, prior);
  if (!t) {
    e.health |= kCurbMatchRejected;
    return std::nullopt;
  }
  const Eigen::Vector2d corrected_xy = t->apply(xy(prior));
  const Pose2d matched{corrected_xy.x(), corrected_xy.y(), wrap_angle(prior.yaw + t->yaw)};
  // The baselines keep their matchers' own answers: a common finish would make them all one matcher.
  const CurbMatchQuality q =
      params_.method == LocalizerMethod::proposed
          ? finish_curb_match(features, matched, local.index, local.tangents, params_.curb_noise)
          : curb_match_quality(features, matched, local.index, local.tangents, params_.curb_noise);
  const Pose2d& z = q.pose;
  e.curb_observation = z;
  e.curb_inlier_ratio = q.inlier_ratio;
  if (q.inlier_ratio < params_.health.min_inlier_ratio) {
    e.health |= kCurbMatchRejected;
    return std::nullopt;
  }
  return PoseObservation{z, q.covariance};
}

// The correction of the prior that the method's matcher finds (a transform of the local frame):
// probabilistic ICP (3.1) or a baseline. nullopt if FMT finds none.
std::optional<Pose2d> Localizer::curb_correction(const std::vector<Eigen::Vector2d>& features_world,
                                                 const MapIndex& local_map, const Pose2d& prior) {
  // Correspondences as far as the prior is uncertain (see icp_window_sigmas).
  const double sigma = std::sqrt(filter_->covariance().topLeftCorner<2, 2>().eigenvalues().real().maxCoeff());
  auto widened = [&](IcpParams p) {
    p.max_correspondence =
        std::max(p.max_correspondence, std::min(params_.icp_window_sigmas * sigma, params_.icp_max_correspondence_m));
    return p;
  };
  switch (params_.method) {
    case LocalizerMethod::proposed: {
      ProbabilisticIcpParams p = params_.probabilistic_icp;
      p.local = widened(p.local);  // the global ICP keeps d_g
      return probabilistic_icp(local_map, features_world, {}, p, rng_).t;
    }
    case LocalizerMethod::icp:
    case LocalizerMethod::icp_obs:
      return icp(local_map, features_world, {}, widened(params_.icp)).t;
    case LocalizerMethod::m_icp: {
      MIcpParams p = params_.m_icp;
      p.icp = widened(p.icp);
      return m_icp(local_map, features_world, {}, p).t;
    }
    case LocalizerMethod::fmt: {
      const FmtResult f = fmt_match(features_world, local_map.points(), xy(prior), params_.fmt);
      if (!f.ok) return std::nullopt;
      return f.correction;
    }
    case LocalizerMethod::gps:
    case LocalizerMethod::intensity:
    case LocalizerMethod::gicp:
      break;  // no curb matcher: process_scan does not ask
  }
  return std::nullopt;
}

// 3.3: the curb observation (x, y, psi) into KF2, if it passes the innovation gate.
// While lost, the filter's heading is in doubt as far as the search's (search_sigmas_): after a kidnap
// of the car the filter, told nothing, keeps its old heading and the certainty it had, and would refuse
// every curb match that turns it back once the position is found again. So a match that leaves the
// position where it is (within the step that restarts the search: see process_scan) is judged with that
// doubt, which is added only if the match passes. One that moves the position is judged as always: it
// would restart the search, which places the car along the road as curbs cannot.
void Localizer::fuse_curbs(const PoseObservation& z, LocalizerEstimate& e) {
  Eigen::Matrix3d doubt = Eigen::Matrix3d::Zero();
  const Eigen::Vector2d moves(z.pose.x - filter_->pose().x, z.pose.y - filter_->pose().y);
  if (lost_.lost() && moves.norm() <= params_.aps.step_m)
    doubt(2, 2) = std::max(0.0, search_sigmas_.z() * search_sigmas_.z() - filter_->covariance()(2, 2));
  if (!fuse_pose(z, curb_rejections_, e, doubt)) e.health |= kCurbMatchRejected;
}

bool Localizer::fuse_pose(const PoseObservation& z, int& rejections, LocalizerEstimate& e,
                          const Eigen::Matrix3d& doubt) {
  const StageTimer timer(stage_ms(e, Stage::fusion));
  const Pose2d prior = filter_->pose();
  const Eigen::Vector3d innovation(z.pose.x - prior.x, z.pose.y - prior.y, wrap_angle(z.pose.yaw - prior.yaw));
  const Eigen::Matrix3d S = filter_->covariance() + doubt + z.covariance;
  if (!gate(innovation.dot(S.ldlt().solve(innovation)), params_.health.gate_curb, rejections)) {
    disagree(innovation.head<2>());
    return false;
  }
  if (!doubt.isZero()) filter_->inflate(doubt);
  filter_->update_curb(Eigen::Vector3d(z.pose.x, z.pose.y, z.pose.yaw), z.covariance);  // KF2
  e.fused_pose = MapObservation{e.stamp_ns, z.pose, in_car_axes(z.covariance, z.pose.yaw), Eigen::Vector2d::Zero()};
  // Curbs along a straight road say nothing of the position along it.
  const Eigen::Vector2d forward(std::cos(prior.yaw), std::sin(prior.yaw));
  const double along_sigma = std::sqrt(forward.dot(z.covariance.topLeftCorner<2, 2>() * forward));
  agree(prior, innovation.head<2>(), along_sigma <= params_.lost.converged_sigma_m, true);
  return true;
}

// gicp: the pose Generalized-ICP of the scan against the map's points around the prior puts the car at,
// with its covariance; nullopt (and why, in e.health) if there is none to use. The target is cut anew
// only when the car has left the part of the map the last one was cut for.
std::optional<Localizer::PoseObservation> Localizer::match_points(const ScanPoints& points, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::point_matching));
  const GicpParams& g = params_.gicp;
  const Pose2d prior = filter_->pose();
  if (!map_.points) {
    e.health |= kNoPointMatch;
    return std::nullopt;
  }
  if (!gicp_target_.covers(xy(prior), g))
    gicp_target_.build(map_.points->points_near(xy(prior), GicpTarget::radius(g)), xy(prior), g);
  // Correspondences as far as the prior is uncertain, as for the curbs (icp_window_sigmas).
  const double sigma = std::sqrt(filter_->covariance().topLeftCorner<2, 2>().eigenvalues().real().maxCoeff());
  const double max_correspondence =
      std::max(g.max_correspondence_m, std::min(g.window_sigmas * sigma, g.max_correspondence_widened_m));
  // The filter's x, y, psi; height, roll and pitch from the last registration (the road's, nearby).
  // (Z-Y-X angles read directly: small pitch and roll never flip as Eigen's eulerAngles may.)
  const Eigen::Matrix3d& last = last_registration_.linear();
  const double pitch = std::asin(std::clamp(-last(2, 0), -1.0, 1.0)), roll = std::atan2(last(2, 1), last(2, 2));
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() =
      (Eigen::AngleAxisd(prior.yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  start.translation() = Eigen::Vector3d(prior.x, prior.y, last_registration_.translation().z());
  const GicpResult r = gicp_match(points.xyz, start, gicp_target_, g, max_correspondence);
  e.point_fitness = r.fitness;
  if (r.status == GicpStatus::few_map_points || r.status == GicpStatus::few_scan_points) {
    e.health |= kNoPointMatch;
    return std::nullopt;
  }
  const Eigen::Matrix3d R = r.pose.linear();
  const Pose2d z{r.pose.translation().x(), r.pose.translation().y(), wrap_angle(std::atan2(R(1, 0), R(0, 0)))};
  e.point_observation = z;
  if (!r.ok()) {
    e.health |= kPointMatchRejected;
    return std::nullopt;
  }
  last_registration_ = r.pose;
  return PoseObservation{z, r.covariance};
}

// 3.2: APS of S against the intensity layer (Eq. 14-18) around the pose after the curb update; nullopt
// (and why, in e.health) if there is no position to use.
std::optional<ApsResult> Localizer::match_intensity(IntensityGrid& S, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::intensity_matching));
  // S holds vehicle-frame cells, so it goes where the curbs just put the car.
  S.pose = filter_->pose();
  const ApsResult aps = aps_match(S, map_.intensity, aps_window(S.pose));
  e.intensity_cells = aps.cells_used;
  if (!aps.ok) {
    e.health |= kNoIntensityMatch;
    return std::nullopt;
  }
  if (aps.peak_on_edge) {
    // The truth may lie beyond the window; or the paint says nothing here (a dashed line's flat
    // stretch): no disagreement to count.
    e.health |= kIntensityMatchRejected;
    return std::nullopt;
  }
  e.intensity_observation = aps.position;
  return aps;
}

// APS's search window: section 3.2's, grown to aps_window_sigmas of the prior's spread along and across
// the car, up to the maxima.
ApsParams Localizer::aps_window(const Pose2d& prior) const {
  const double c = std::cos(prior.yaw), s = std::sin(prior.yaw);
  Eigen::Matrix2d to_vehicle;
  to_vehicle << c, s, -s, c;
  const Eigen::Matrix2d spread = to_vehicle * filter_->covariance().topLeftCorner<2, 2>() * to_vehicle.transpose();
  ApsParams aps = params_.aps;
  auto range = [&](double variance, double paper_range, double max_range) {
    const double wanted = std::clamp(params_.aps_window_sigmas * std::sqrt(std::max(variance, 0.0)), paper_range,
                                     std::max(paper_range, max_range));
    // Whole steps, so the window stays symmetric about the prior.
    return std::floor(wanted / aps.step_m + kWholeStepTolerance) * aps.step_m;
  };
  aps.longitudinal_range_m =
      range(spread(0, 0), params_.aps.longitudinal_range_m, params_.aps_max_longitudinal_range_m);
  aps.lateral_range_m = range(spread(1, 1), params_.aps.lateral_range_m, params_.aps_max_lateral_range_m);
  aps.prior_longitudinal_sigma_m = std::sqrt(std::max(spread(0, 0), 0.0));
  return aps;
}

// 3.3: the APS position into KF2, if it passes the innovation gate; only along the road when the curbs
// were matched in this scan (see aps_longitudinal_only_with_curbs).
void Localizer::fuse_intensity(const ApsResult& aps, const IntensityGrid& grid, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::fusion));
  const Pose2d prior = filter_->pose();
  const Eigen::Vector2d innovation = aps.position - xy(prior);
  // APS's claim, widened by S's redundancy (IntensityGrid::redundancy), then scaled by what its
  // innovations have shown of it so far (innovation_scale.hpp), on straights or in bends.
  const Eigen::Matrix2d claimed = aps.covariance * params_.aps_covariance_scale * grid.redundancy;
  InnovationScale& scale = grid.turning ? aps_scale_turning_ : aps_scale_straight_;
  const Eigen::Matrix2d R = scaled_along_across(claimed, prior.yaw, scale.scale());
  // APS matched at the prior's heading: a heading error moves its answer by yaw_coupling per radian,
  // so the observation is z = p + J (psi_prior - psi) and its gate counts the heading's doubt; in a
  // bend or with paint on one side of the car the update then also corrects the heading.
  const Eigen::Vector2d& J = aps.yaw_coupling;
  const Eigen::Matrix<double, 2, 3> H = intensity_observation_matrix(J);
  const Eigen::Matrix2d HPH = H * filter_->covariance() * H.transpose();  // the prior's doubt of z
  const Eigen::Matrix2d S = HPH + R;
  if (!gate(innovation.dot(S.ldlt().solve(innovation)), params_.health.gate_intensity, intensity_rejections_)) {
    e.health |= kIntensityMatchRejected;
    disagree(innovation);
    return;
  }
  // Beyond the paper: an axis along which Eq. 14's distribution is about as wide as the search window
  // carries no information (a solid line along the road and nothing marking the position along it);
  // its centre of mass only follows the map's noise and the window's edges, and a drift it starts is
  // never taken back. Such an axis is left to the other sensors.
  // Where the window was grown to the prior's spread (a cold start, GPS alone), it must also be no
  // wider than what the filter already believes: a broad bump of map noise in the wide window looked
  // informative against the window while it said less than GPS (intersections: a first match 3 m
  // off moved the car 1.45 m).
  const bool curbs_hold_lateral =
      params_.aps_longitudinal_only_with_curbs && e.curb_observation && !(e.health & kCurbMatchRejected);
  const Eigen::Vector2d forward(std::cos(prior.yaw), std::sin(prior.yaw)), left(-forward.y(), forward.x());
  const Eigen::Matrix2d P = filter_->covariance().topLeftCorner<2, 2>();
  // The window on this axis grown beyond the paper's to the prior's spread (aps_window).
  auto grown = [&](const Eigen::Vector2d& u, double paper_range) {
    return params_.aps_window_sigmas * std::sqrt(u.dot(P * u)) > paper_range;
  };
  auto informative = [&](int axis, const Eigen::Vector2d& u, double paper_range) {
    return aps.spread_ratio[axis] <= params_.aps_max_spread_ratio &&
           (!grown(u, paper_range) || u.dot(aps.covariance * u) <= u.dot(P * u));
  };
  const double along_range = params_.aps.longitudinal_range_m;
  // Along the road the best offset must also beat the other peaks there, the prior counted
  // (ApsResult::along_margin, aps_min_along_margin). In a window grown to the prior's doubt, an answer far
  // out along the road is what paint a dash period from the truth gives (static_campus, seeds 3 and 4,
  // intensity: 5.5 and 3.8 m from the GPS's guess, the first beating the truth by 10-30 of Eq. 14's log P
  // scan after scan): it must beat the rest by the wide search's margin. One within the prior's spread
  // confirms the GPS: the aliases a period away from it lie in the prior's tail.
  const bool grown_along = grown(forward, along_range);
  const bool near_prior =
      std::abs(forward.dot(innovation)) <= params_.aps_grown_within_sigmas * std::sqrt(forward.dot(P * forward));
  const double min_margin =
      grown_along && !near_prior ? params_.relocalization.min_aps_margin : params_.aps_min_along_margin;
  const bool along = confirmed_along(informative(0, forward, along_range) && aps.along_margin >= min_margin,
                                     grown_along, forward.dot(innovation));
  const bool across = informative(1, left, params_.aps.lateral_range_m) && !curbs_hold_lateral;
  if (along && across)
    filter_->update_intensity(aps.position, R, J);  // KF2
  else if (along || across)
    filter_->update_intensity_along(aps.position, R, along ? forward : left, J);
  else
    e.health |= kIntensityAmbiguous;
  if (along || across) {
    // What the filter believed of it, an axis not taken infinite.
    const double infinite = std::numeric_limits<double>::infinity();
    Eigen::Matrix3d taken = Eigen::Vector3d(0, 0, infinite).asDiagonal();
    taken.topLeftCorner<2, 2>() = R;
    taken = in_car_axes(taken, prior.yaw);
    for (int axis : {0, 1})
      if (!(axis == 0 ? along : across))
        taken.row(axis).setZero(), taken.col(axis).setZero(), taken(axis, axis) = infinite;
    e.fused_intensity = MapObservation{e.stamp_ns, {aps.position.x(), aps.position.y(), prior.yaw}, taken, J};
    const Eigen::Matrix2d to_vehicle = Eigen::Rotation2Dd(-prior.yaw).toRotationMatrix();
    const Eigen::Vector2d nu = to_vehicle * innovation;
    const Eigen::Vector2d prior_variance = (to_vehicle * HPH * to_vehicle.transpose()).diagonal();
    const double unused = std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector2d claimed_variance = (to_vehicle * claimed * to_vehicle.transpose()).diagonal();
    // Learnt while tracking only: lost, the filter's own variance is not yet to be believed.
    if (!lost_.lost())
      scale.add(nu, prior_variance, {along ? claimed_variance.x() : unused, across ? claimed_variance.y() : unused});
    agree(prior, innovation, along, across);
  }
}

// In a window grown to the prior's doubt (a cold start, a kidnap) APS searches as the relocalization
// does, and dashed lines repeat along the road: a single scan's S put the car one dash period off with
// full confidence (dynamic_campus under harsh, seed 1: 9.4 m for the whole run). Its position along the
// road is taken, as the relocalization's places are, only when the next scan's match agrees with it
// (within relocalization.confirm_distance_m); held back meanwhile. In the paper's window: at once.
bool Localizer::confirmed_along(bool informative, bool grown, double innovation_along) {
  if (!informative || !grown) {
    held_along_.reset();
    return informative;
  }
  if (held_along_ && std::abs(innovation_along - *held_along_) <= params_.relocalization.confirm_distance_m) {
    held_along_.reset();
    return true;
  }
  held_along_ = innovation_along;
  return false;
}

double Localizer::position_sigma() const {
  return std::sqrt(filter_->covariance().topLeftCorner<2, 2>().eigenvalues().real().maxCoeff());
}

void Localizer::agree(const Pose2d& prior, const Eigen::Vector2d& innovation, bool along, bool across) {
  const bool was_lost = lost_.lost();
  lost_.agree(along, across, position_sigma(), Eigen::Rotation2Dd(-prior.yaw) * innovation);
  if (!lost_.lost()) {
    if (was_lost) {
      // Found and confirmed (perhaps by the narrow matchers while a search ran): the search ends, and
      // the GPS's level is learnt anew against the pose now trusted.
      relocalizer_.finish();
      judge_gps_jump(filter_->pose());
      gps_steps_.restart();
      search_sigmas_.setZero();
    } else {
      // The map corrected the filter: every GPS innovation moves by as much, and that is no step.
      gps_steps_.shift(xy(prior) - xy(filter_->pose()));
    }
  }
}

void Localizer::disagree(const Eigen::Vector2d& innovation, bool gps) {
  const bool was_searching = lost_.searching();
  lost_.disagree({time_ns_, innovation, gps});
  if (!lost_.searching() || was_searching) {
    if (lost_.searching()) widen_to(lost_.disagreements(time_ns_));
    return;
  }
  trusted_ = {filter_->pose(), filter_->covariance(), odometry_};
  lost_by_gps_ = false;
  for (const Disagreement& d : lost_.disagreements(time_ns_)) lost_by_gps_ = lost_by_gps_ || d.gps;
  // Only the GPS disagrees and the map's matches still agree: first see whether they go on agreeing
  // with the filter as it is (the GPS jumped) before searching anywhere else.
  if (lost_.only_gps_disagrees(time_ns_))
    lost_.found();
  else
    widen_to(lost_.disagreements(time_ns_));
}

void Localizer::widen_to(const std::deque<Disagreement>& refused) {
  double reach = 0;
  for (const Disagreement& d : refused) reach = std::max(reach, d.innovation.norm());
  const RelocalizationParams& r = params_.relocalization;
  const double sigma = reach / r.lost_offset_sigmas, yaw_sigma = r.lost_yaw_sigma_deg / kDegPerRad;
  search_sigmas_ = search_sigmas_.cwiseMax(Eigen::Vector3d(sigma, sigma, yaw_sigma));
  if (trusted_) return;
  // A cold start: the filter's spread is the GPS's guess, and grows with what refutes it, which widens
  // the narrow matchers' windows as well.
  const Eigen::Matrix3d& P = filter_->covariance();
  filter_->inflate(Eigen::Vector3d(std::max(0.0, sigma * sigma - P(0, 0)), std::max(0.0, sigma * sigma - P(1, 1)),
                                   std::max(0.0, yaw_sigma * yaw_sigma - P(2, 2)))
                       .asDiagonal());
}

// While lost: a share of the wide searches (relocalization.hpp) over the window the filter's spread
// spans; the filter moves to what they find.
void Localizer::relocalize(IntensityGrid* S, LocalizerEstimate& e) {
  const StageTimer timer(stage_ms(e, Stage::intensity_matching));
  e.wide_search = true;
  const Pose2d prior = filter_->pose();
  if (!relocalizer_.active()) start_relocalization();
  std::vector<Eigen::Vector2d> curbs_world;
  if (uses_curbs(params_.method) && features_.curbs.size() >= size_t(params_.relocalization.curbs.min_curbs))
    for (const auto& f : features_.curbs) curbs_world.push_back(vehicle_to_world(prior, f));
  // The map's curbs around the car only when there are curbs to search with (match_curbs cuts its own).
  const LocalCurbs local =
      curbs_world.empty() ? LocalCurbs{MapIndex({}), {}} : local_curbs(map_.curbs, xy(prior), params_.map_window_m);
  const std::optional<Relocation> found = relocalizer_.step(uses_intensity(params_.method) ? S : nullptr,
                                                            map_.intensity, curbs_world, local.index, prior, odometry_);
  // A place across the road where the filter already is, is no news: moving there would restart the
  // search, and with it the other matcher's unfinished search or a whole place waiting to be found
  // again (curbs place the car across the road every other scan; APS's search takes several).
  if (found && !found->longitudinal) {
    const Pose2d change = relative(prior, found->pose);
    const RelocalizationParams& r = params_.relocalization;
    if (std::abs(change.y) <= r.confirm_distance_m && std::abs(change.yaw) <= r.confirm_yaw_deg / kDegPerRad) return;
  }
  if (found) move_to(*found);
}

void Localizer::start_relocalization() {
  const RelocalizationParams& r = params_.relocalization;
  const Pose2d prior = filter_->pose();
  const Eigen::Vector3d sigmas = vehicle_sigmas(filter_->covariance(), prior).cwiseMax(search_sigmas_);
  auto half = [&](double sigma, double max_range) {
    return std::clamp(r.window_sigmas * sigma, std::min(r.min_range_m, max_range), max_range);
  };
  const Eigen::Vector3d ranges(
      half(sigmas.x(), r.max_longitudinal_m), half(sigmas.y(), r.max_lateral_m),
      // at least a coarse step either side: a peak is on the window's edge beyond half
      // of one, so a narrower window would refuse every place not at the prior's heading
      std::clamp(r.window_sigmas * sigmas.z(), r.aps.coarse_yaw_step_rad, r.max_yaw_deg / kDegPerRad));
  // The filter before it was lost, and the newest GPS fix; a cold start has only the filter as the
  // GPS set it up.
  std::vector<Hypothesis> hypotheses;
  auto hypothesis = [&](const PoseBelief& belief) {
    const PoseBelief now = carried(belief);
    hypotheses.push_back({now.pose, vehicle_sigmas(now.covariance, now.pose)});
  };
  if (trusted_) hypothesis(*trusted_);
  // The GPS is a hypothesis of its own after a cold start or when it disagreed too; not when it has
  // jumped or gone stale, nor when only the map disagreed (the GPS then agrees with the filter, and its
  // metres of doubt would only let the map's ambiguities in).
  if (last_fix_ && (!trusted_ || lost_by_gps_) && !gps_fault_level_ && !(input_health(time_ns_) & kNoGps))
    hypothesis(*last_fix_);
  if (hypotheses.empty()) hypotheses.push_back({prior, sigmas});
  relocalizer_.start(ranges, hypotheses, odometry_);
}

void Localizer::move_to(const Relocation& found) {
  relocalizer_.stop();
  // What the search placed is no longer in doubt; the position along the road, if it was not placed,
  // is as doubtful as before, and the next search spans it again.
  search_sigmas_.tail<2>().setZero();
  if (found.longitudinal) search_sigmas_.x() = 0;
  if (!found.heading) search_sigmas_.z() = params_.relocalization.lost_yaw_sigma_deg / kDegPerRad;
  Eigen::Matrix3d covariance = found.covariance;
  if (!found.longitudinal) {
    // The filter's doubt along the road stays; across it and in heading, the search's.
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    R.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(found.pose.yaw).toRotationMatrix();
    const Eigen::Matrix3d old_vehicle = R.transpose() * filter_->covariance() * R;
    const Eigen::Matrix3d new_vehicle = R.transpose() * found.covariance * R;
    const double yaw_variance = (found.heading ? new_vehicle : old_vehicle)(2, 2);
    covariance = R * Eigen::Vector3d(old_vehicle(0, 0), new_vehicle(1, 1), yaw_variance).asDiagonal() * R.transpose();
  }
  UnplacedAxes unplaced;
  if (!found.longitudinal)
    unplaced = {Eigen::Vector2d(std::cos(found.pose.yaw), std::sin(found.pose.yaw)), !found.heading};
  filter_->reset_pose(found.pose, covariance, unplaced);
  if (!found.longitudinal) return;  // still lost: the next scan searches again, narrower across
  lost_.found();
  judge_gps_jump(found.pose);
}

// Moved by the odometry since, with odometry's doubt over that distance and turn (the filter's random
// walks per metre and per radian turned; not its per-second term, nor the heading's doubt turned into
// position by the drive).
Localizer::PoseBelief Localizer::carried(const PoseBelief& belief) const {
  const Pose2d moved = relative(belief.odometry, odometry_);
  const double distance = std::hypot(moved.x, moved.y);
  const PoseFilterParams& q = params_.filter;
  const double position = q.position_per_sqrt_m * q.position_per_sqrt_m * distance;
  double yaw = q.yaw_per_sqrt_m * q.yaw_per_sqrt_m * distance;
  if (q.yaw_per_sqrt_rad > 0) yaw += q.yaw_per_sqrt_rad * q.yaw_per_sqrt_rad * std::abs(moved.yaw);
  return {belief.pose.compose(moved),
          belief.covariance + Eigen::Vector3d(position, position, yaw).asDiagonal().toDenseMatrix(), odometry_};
}

// Who jumped, once the map has placed the car? If it is about where the filter had it before it was
// lost while the GPS had stepped, the GPS did. A step away from the filter is a fault: the fixes are
// rejected until they step back. A step towards it ends one the detector had not caught (a jump that
// came before its level was learnt, at a cold start): the new level is learnt instead. Rejected, such
// a GPS waited for a level it would never return to (gps_degraded: GPS rejected for the last 70 s).
void Localizer::judge_gps_jump(const Pose2d& placed) {
  const std::optional<Eigen::Vector2d>& before = gps_steps_.level();
  if (gps_stepped_ && trusted_ && last_gps_step_ && before &&
      (xy(placed) - xy(carried(*trusted_).pose)).norm() < 0.5 * last_gps_step_->norm()) {
    if ((*before + *last_gps_step_).norm() > before->norm())
      gps_fault_level_ = before;
    else
      gps_steps_.restart();
  }
  gps_stepped_ = false;
}

void Localizer::report_pose(LocalizerEstimate& e) {
  if (filter_) {
    e.pose = filter_->car_pose();
    // The calibration's residual on top of the filter's doubt (a consider term), but for a mount yaw the
    // filter learns: its doubt of that is in the car's covariance already.
    const MountUncertainty& m = params_.mount_uncertainty;
    const double t = m.translation_sigma_m, yaw = filter_->learns_mount_yaw() ? 0.0 : m.yaw_sigma_deg / kDegPerRad;
    e.covariance = filter_->car_covariance() + Eigen::Vector3d(t * t, t * t, yaw * yaw).asDiagonal().toDenseMatrix();
    if (filter_->learns_mount_yaw())
      e.mount_yaw = MountYawEstimate{filter_->mount_yaw(), std::sqrt(filter_->mount_yaw_variance())};
    if (gps_fault_level_) e.health |= kGpsRejected;
    if (lost_.lost()) {
      e.health |= kLost;  // the bounds stay infinite
    } else {
      const ProtectionBounds b =
          protection_bounds(e.covariance, e.pose, lost_.disagreements(e.stamp_ns), params_.integrity);
      e.protection_lateral_m = b.lateral_m;
      e.protection_longitudinal_m = b.longitudinal_m;
    }
  } else {
    e.health |= kNotInitialized;
    e.covariance = Eigen::Matrix3d::Identity() * kUnknownVariance;
  }
}

}  // namespace lidarloop
