#include "localizer/localizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Dense>

#include "common/units.hpp"
#include "localizer/aps_matcher.hpp"
#include "localizer/curb_detector.hpp"
#include "localizer/curb_match_covariance.hpp"
#include "localizer/deskew.hpp"
#include "localizer/driving_corridor.hpp"
#include "localizer/obstacle_rejection.hpp"

namespace lidarloop {
namespace {

// Before the first fix there is no pose: the estimate says so with this (m^2, rad^2) on the diagonal.
constexpr double kUnknownVariance = 1e6;

class Stopwatch {
 public:
  double lap_ms() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

Eigen::Vector2d xy(const Pose2d& p) { return {p.x, p.y}; }

}  // namespace

CanMotion can_motion(const CanFrame& f, const VehicleModelParams& vehicle) {
  return {0.5 * (f.wheel_speed_mps[2] + f.wheel_speed_mps[3]),  // rear axle centre
          f.steering_wheel_angle_rad / vehicle.steering_ratio};
}

std::string describe_health(uint32_t flags) {
  static const std::array<const char*, kHealthFlagCount> names = {
      "not initialised", "CAN gap",        "no GPS",           "invalid points",     "empty scan",
      "no corridor",     "no ground plane", "few curbs",        "curb match rejected", "no intensity match",
      "intensity match rejected"};
  if (flags == 0) return "ok";
  std::string out;
  for (int i = 0; i < kHealthFlagCount; ++i)
    if (flags & (1u << i)) out += (out.empty() ? "" : ", ") + std::string(names[size_t(i)]);
  return out;
}

const char* stage_name(Stage s) {
  static const std::array<const char*, kStageCount> names = {
      "deskew", "corridor", "obstacles", "curb_detection", "curb_features", "curb_matching", "intensity_matching",
      "fusion"};
  return names[size_t(s)];
}

Localizer::Localizer(HdMap& map, const LocalizerParams& params)
    : map_(map),
      params_(params),
      frame_(map.curbs.map().origin),
      rng_(params.seed),
      predictor_(params.vehicle),
      accumulator_(params.curb_features.frames) {}

void Localizer::initialize(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& covariance) {
  predict_to(stamp_ns);
  filter_.emplace(pose, covariance, params_.filter);
}

std::optional<Pose2d> Localizer::pose() const {
  if (!filter_) return std::nullopt;
  return filter_->pose();
}

void Localizer::predict_to(int64_t t_ns) {
  if (t_ns <= time_ns_) return;
  const Pose2d before = odometry_;
  const double dt = double(t_ns - time_ns_) / kNsPerS;
  odometry_ = predictor_.advance(odometry_, speed_, steer_, t_ns - time_ns_, params_.max_prediction_step_s);
  time_ns_ = t_ns;
  if (!filter_) return;
  // The filter moves by the odometry's increment in its own frame.
  const Pose2d step = relative(before, odometry_);
  filter_->predict(filter_->pose().compose(step), std::hypot(step.x, step.y), dt);
  const bool can_stale =
      !last_can_ns_ || double(t_ns - *last_can_ns_) / kNsPerS > params_.health.can_timeout_s;
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

void Localizer::on_gps(const GpsFix& fix) {
  if (fix.status == GpsStatus::no_fix) return;
  if (!std::isfinite(fix.lat_deg) || !std::isfinite(fix.lon_deg) || !std::isfinite(fix.heading_rad)) return;
  predict_to(fix.stamp_ns);
  const Eigen::Vector2d p = frame_.to_local(fix.lat_deg, fix.lon_deg);
  const GpsNoise& n = params_.gps_noise;
  auto variance = [&](double reported, double floor) {
    return std::isfinite(reported) ? std::max(reported, floor * floor) : floor * floor;
  };
  const Eigen::Matrix3d R = Eigen::Vector3d(variance(fix.position_covariance[0], n.min_sigma_m),
                                            variance(fix.position_covariance[4], n.min_sigma_m),
                                            variance(fix.heading_variance, n.min_heading_sigma_rad))
                                .asDiagonal();
  last_gps_ns_ = fix.stamp_ns;
  if (!filter_) {
    // One fix is as good as the receiver says; the scale is for the correlation between many.
    filter_.emplace(Pose2d{p.x(), p.y(), wrap_angle(fix.heading_rad)}, R, params_.filter);
    return;
  }
  filter_->update_gps(Eigen::Vector3d(p.x(), p.y(), fix.heading_rad), R * n.variance_scale);  // KF1
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
  Stopwatch total, watch;
  LocalizerEstimate e;
  uint32_t last_t = 0;
  for (const LidarPoint& p : cloud.points) last_t = std::max(last_t, p.t_ns);
  e.stamp_ns = std::max(cloud.stamp_ns + int64_t(last_t), time_ns_);
  predict_to(e.stamp_ns);
  e.health = input_health(e.stamp_ns);
  const Pose2d since_previous =
      previous_scan_odometry_ ? relative(*previous_scan_odometry_, odometry_) : Pose2d{};
  previous_scan_odometry_ = odometry_;
  features_ = {};

  auto finish = [&]() {
    if (filter_) {
      e.pose = filter_->pose();
      e.covariance = filter_->covariance();
    } else {
      e.health |= kNotInitialized;
      e.covariance = Eigen::Matrix3d::Identity() * kUnknownVariance;
    }
    e.total_ms = total.lap_ms();
    return e;
  };
  const LocalizerMethod method = params_.method;
  if (method == LocalizerMethod::gps) return finish();

  const ScanPoints points =
      params_.deskew ? deskew(cloud, params_.lidar_mount, {speed_, predictor_.yaw_rate()}, int64_t(last_t))
                     : to_vehicle_frame(cloud, params_.lidar_mount);
  e.points = points.size();
  e.dropped_points = points.dropped;
  if (points.dropped > 0) e.health |= kInvalidPoints;
  e.stage_ms[size_t(Stage::deskew)] = watch.lap_ms();
  if (e.points < size_t(std::max(params_.health.min_scan_points, 1)) || !filter_) {
    if (e.points < size_t(std::max(params_.health.min_scan_points, 1))) e.health |= kEmptyScan;
    accumulator_.add({}, since_previous);  // keep the older frames where they are relative to the car
    return finish();
  }
  const Pose2d prior = filter_->pose();

  // 2.1: the driving corridor, and the ground and obstacles inside it.
  std::vector<size_t> ground;  // indices into points: the road surface
  std::vector<Eigen::Vector2d> obstacles;
  if (removes_obstacles(method)) {
    const CorridorParams& cp = params_.corridor;
    const double half = 0.5 * std::max(cp.width_cells, cp.height_cells) * cp.cell_m;
    const DrivingCorridor corridor = extract_driving_corridor(map_.curbs.window(xy(prior), half), prior, cp);
    std::vector<size_t> inside;
    std::vector<Eigen::Vector3d> inside_xyz;
    const bool have_corridor = !corridor.mask.empty();
    if (!have_corridor) e.health |= kNoCorridor;
    for (size_t i = 0; i < points.size(); ++i)
      if (!have_corridor || corridor.contains(points.xyz[i].head<2>())) {
        inside.push_back(i);
        inside_xyz.push_back(points.xyz[i]);
      }
    e.corridor_points = inside.size();
    e.stage_ms[size_t(Stage::corridor)] = watch.lap_ms();
    const ObstacleSplit split = reject_obstacles(inside_xyz, params_.obstacles);
    if (!split.plane_ok) e.health |= kNoGroundPlane;
    for (size_t k : split.ground_index)  // the road surface, for S (see IntensityGridParams::max_height)
      if (!split.plane_ok || distance_to_plane(split.plane, inside_xyz[k]) <= params_.intensity_grid.max_height)
        ground.push_back(inside[k]);
    for (const auto& o : split.obstacles) obstacles.push_back(o.head<2>());
    e.obstacle_points = obstacles.size();
    e.stage_ms[size_t(Stage::obstacles)] = watch.lap_ms();
  }
  features_.obstacles = obstacles;

  // 2.2.1 and 3.1: curbs.
  if (uses_curbs(method)) {
    std::vector<Eigen::Vector2d> curbs = detect_curbs(points.xyz, points.ring, params_.curb_detector);
    e.curbs_detected = curbs.size();
    e.stage_ms[size_t(Stage::curb_detection)] = watch.lap_ms();
    if (removes_obstacles(method))
      curbs = reject_near_obstacles(curbs, obstacles, params_.curb_features.obstacle_distance);
    accumulator_.add(curbs, since_previous);  // Eq. 4-5
    std::vector<Eigen::Vector2d> features =
        beam_model(accumulator_.curbs(), accumulator_.launch_points(), params_.curb_features);  // Eq. 6-7
    e.curb_features = features.size();
    e.stage_ms[size_t(Stage::curb_features)] = watch.lap_ms();
    match_curbs(features, e);
    features_.curbs = std::move(features);
  }

  // 2.2.2 and 3.2: intensity.
  if (uses_intensity(method)) {
    std::vector<Eigen::Vector3d> ground_xyz;
    std::vector<double> intensities;
    ground_xyz.reserve(ground.size());
    intensities.reserve(ground.size());
    for (size_t i : ground) {
      ground_xyz.push_back(points.xyz[i]);
      intensities.push_back(points.intensity[i]);
    }
    match_intensity(ground_xyz, intensities, e);
  }
  return finish();
}

void Localizer::match_curbs(const std::vector<Eigen::Vector2d>& features, LocalizerEstimate& e) {
  Stopwatch watch;
  if (features.size() < size_t(params_.health.min_curbs)) {
    e.health |= kFewCurbs;
    return;
  }
  const Pose2d prior = filter_->pose();
  std::vector<Eigen::Vector2d> world;
  world.reserve(features.size());
  for (const auto& f : features) world.push_back(vehicle_to_world(prior, f));

  // Correspondences as far as the prior is uncertain (see icp_window_sigmas).
  const double sigma = std::sqrt(filter_->covariance().topLeftCorner<2, 2>().eigenvalues().real().maxCoeff());
  auto widened = [&](IcpParams p) {
    p.max_correspondence =
        std::max(p.max_correspondence, std::min(params_.icp_window_sigmas * sigma, params_.icp_max_correspondence_m));
    return p;
  };
  // The map's curbs around the prior in a small KD-tree of their own: the matchers' thousands of
  // nearest-neighbour queries are then cheaper than in the whole map's tree.
  std::vector<Eigen::Vector2d> local_points, local_tangents;
  for (size_t i : map_.curbs.window_indices(xy(prior), params_.map_window_m)) {
    local_points.push_back(map_.curbs.points()[i]);
    local_tangents.push_back(map_.curbs.tangents()[i]);
  }
  const MapIndex local_map(local_points);
  Pose2d t;
  switch (params_.method) {
    case LocalizerMethod::proposed: {
      ProbabilisticIcpParams p = params_.probabilistic_icp;
      p.local = widened(p.local);  // the global ICP keeps d_g
      t = probabilistic_icp(local_map, world, {}, p, rng_).t;
      break;
    }
    case LocalizerMethod::icp:
    case LocalizerMethod::icp_obs:
      t = icp(local_map, world, {}, widened(params_.icp)).t;
      break;
    case LocalizerMethod::m_icp: {
      MIcpParams p = params_.m_icp;
      p.icp = widened(p.icp);
      t = m_icp(local_map, world, {}, p).t;
      break;
    }
    case LocalizerMethod::fmt: {
      const FmtResult f = fmt_match(world, local_points, xy(prior), params_.fmt);
      if (!f.ok) {
        e.stage_ms[size_t(Stage::curb_matching)] += watch.lap_ms();
        e.health |= kCurbMatchRejected;
        return;
      }
      t = f.correction;
      break;
    }
    default:
      return;
  }
  const Eigen::Vector2d corrected_xy = t.apply(xy(prior));
  const Pose2d z{corrected_xy.x(), corrected_xy.y(), wrap_angle(prior.yaw + t.yaw)};
  const CurbMatchQuality q = curb_match_quality(features, z, local_map, local_tangents, params_.curb_noise);
  e.curb_observation = z;
  e.curb_inlier_ratio = q.inlier_ratio;
  e.stage_ms[size_t(Stage::curb_matching)] += watch.lap_ms();
  if (q.inlier_ratio < params_.health.min_inlier_ratio) {
    e.health |= kCurbMatchRejected;
    return;
  }
  Eigen::Vector3d innovation(z.x - prior.x, z.y - prior.y, wrap_angle(z.yaw - prior.yaw));
  const Eigen::Matrix3d S = filter_->covariance() + q.covariance;
  if (!gate(innovation.dot(S.ldlt().solve(innovation)), params_.health.gate_curb, curb_rejections_)) {
    e.health |= kCurbMatchRejected;
    return;
  }
  filter_->update_curb(Eigen::Vector3d(z.x, z.y, z.yaw), q.covariance);  // KF2
  e.stage_ms[size_t(Stage::fusion)] += watch.lap_ms();
}

void Localizer::match_intensity(const std::vector<Eigen::Vector3d>& ground, const std::vector<double>& intensities,
                                LocalizerEstimate& e) {
  Stopwatch watch;
  const Pose2d prior = filter_->pose();
  // The prior's spread along and across the car sets the search window (see aps_window_sigmas).
  const double c = std::cos(prior.yaw), s = std::sin(prior.yaw);
  Eigen::Matrix2d to_vehicle;
  to_vehicle << c, s, -s, c;
  const Eigen::Matrix2d spread = to_vehicle * filter_->covariance().topLeftCorner<2, 2>() * to_vehicle.transpose();
  ApsParams aps_params = params_.aps;
  auto window = [&](double variance, double paper_range, double max_range) {
    const double wanted = std::clamp(params_.aps_window_sigmas * std::sqrt(std::max(variance, 0.0)), paper_range,
                                     std::max(paper_range, max_range));
    // Whole steps, so the window stays symmetric about the prior.
    return std::floor(wanted / aps_params.step_m + 1e-9) * aps_params.step_m;
  };
  aps_params.longitudinal_range_m =
      window(spread(0, 0), params_.aps.longitudinal_range_m, params_.aps_max_longitudinal_range_m);
  aps_params.lateral_range_m = window(spread(1, 1), params_.aps.lateral_range_m, params_.aps_max_lateral_range_m);
  const IntensityGrid S = build_intensity_grid(ground, intensities, prior, params_.intensity_grid);  // Eq. 8
  const ApsResult aps = aps_match(S, map_.intensity, aps_params);  // Eq. 14-18
  e.intensity_cells = aps.cells_used;
  e.stage_ms[size_t(Stage::intensity_matching)] += watch.lap_ms();
  if (!aps.ok) {
    e.health |= kNoIntensityMatch;
    return;
  }
  if (aps.peak_on_edge) {
    e.health |= kIntensityMatchRejected;
    return;
  }
  e.intensity_observation = aps.position;
  const Eigen::Vector2d innovation = aps.position - xy(prior);
  const Eigen::Matrix2d R = aps.covariance * params_.aps_covariance_scale;
  const Eigen::Matrix2d S2 = filter_->covariance().topLeftCorner<2, 2>() + R;
  if (!gate(innovation.dot(S2.ldlt().solve(innovation)), params_.health.gate_intensity, intensity_rejections_)) {
    e.health |= kIntensityMatchRejected;
    return;
  }
  if (params_.aps_longitudinal_only_with_curbs && e.curb_observation && !(e.health & kCurbMatchRejected))
    filter_->update_intensity_along(aps.position, R, Eigen::Vector2d(std::cos(prior.yaw), std::sin(prior.yaw)));
  else
    filter_->update_intensity(aps.position, R);  // KF2
  e.stage_ms[size_t(Stage::fusion)] += watch.lap_ms();
}

}  // namespace lidarloop
