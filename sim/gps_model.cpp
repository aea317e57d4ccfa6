#include "sim/gps_model.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace lidarloop {
namespace {

constexpr double kNanosecondsPerSecond = 1e9;
constexpr double kSecondsPerNanosecond = 1e-9;
// Variance reported without a fix: so large that a consumer which ignores the status still gives
// the fix no weight (NavSatFix has no "unknown" marker besides the covariance type).
constexpr double kNoFixVariance = 1e6;
// Indices of the diagonal of a row-major 3x3 covariance (east, north, up).
constexpr int kEast = 0, kNorth = 4, kUp = 8;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

bool finite_non_negative(double v) { return std::isfinite(v) && v >= 0; }
bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

// One step of the exact discretisation of a first-order Gauss-Markov process: the stationary
// standard deviation stays `sigma` and the correlation time `tau` whatever dt is.
double gauss_markov_step(double b, double dt_s, double sigma, double tau_s, double n) {
  const double phi = std::exp(-dt_s / tau_s);
  return phi * b + sigma * std::sqrt(1.0 - phi * phi) * n;
}

int64_t period_for(double rate_hz) { return std::llround(kNanosecondsPerSecond / rate_hz); }

bool zone_applies(const GpsZone& zone, int64_t t_ns, const Pose2d& truth) {
  const bool in_space = zone.radius_m == 0 || (Eigen::Vector2d(truth.x, truth.y) - zone.centre).norm() <= zone.radius_m;
  return in_space && zone.from_ns <= t_ns && t_ns < zone.to_ns;
}

}  // namespace

GpsConfig gps_config_for(Realism realism) {
  GpsConfig c;
  if (realism == Realism::ideal) c.antenna_xyz.setZero();
  return c;
}

GpsModel::GpsModel(const GpsConfig& config, const LocalFrame& frame, uint64_t seed)
    : config_(config), frame_(frame), rng_(seed) {
  require(finite_positive(config.rate_hz), "GPS config: rate_hz must be positive");
  require(finite_non_negative(config.bias_sigma_m) && finite_non_negative(config.white_sigma_m) &&
              finite_non_negative(config.vertical_sigma_m) && finite_non_negative(config.heading_bias_sigma_rad) &&
              finite_non_negative(config.heading_white_sigma_rad),
          "GPS config: noise sigmas must not be negative");
  require(finite_positive(config.bias_tau_s) && finite_positive(config.heading_bias_tau_s),
          "GPS config: correlation times must be positive");
  for (const GpsZone& zone : config.zones) {
    require(finite_non_negative(zone.radius_m), "GPS zone: radius must not be negative");
    require(zone.centre.allFinite() && zone.jump_m.allFinite(), "GPS zone: centre and jump must be finite");
  }
  require(config.antenna_xyz.allFinite(), "GPS config: antenna_xyz must be finite");
}

GpsFix GpsModel::sample(int64_t t_ns, const Pose2d& truth) {
  // Times count from scenario start; last_ns_ < 0 marks "no sample yet".
  if (t_ns < 0) throw std::logic_error("GpsModel::sample called with a negative time");
  if (t_ns < last_ns_) throw std::logic_error("GpsModel::sample called with a time earlier than the previous one");

  // Every call draws seven normals in this order -- bias east, north, heading; white east, north, up,
  // heading -- whether or not there is a fix. So the error at sample k depends only on the seed and k
  // (and the sample times): an outage does not shift the noise of the fixes after it, and the bias
  // keeps evolving through it, as the real error process runs on without a fix.
  const double n_bias_e = normal_(rng_), n_bias_n = normal_(rng_), n_bias_h = normal_(rng_);
  const double n_white_e = normal_(rng_), n_white_n = normal_(rng_), n_white_u = normal_(rng_),
               n_white_h = normal_(rng_);

  if (last_ns_ < 0) {
    // First sample: the receiver has been on for a while, so the bias is drawn from its stationary law.
    bias_ = config_.bias_sigma_m * Eigen::Vector2d(n_bias_e, n_bias_n);
    heading_bias_ = config_.heading_bias_sigma_rad * n_bias_h;
  } else {
    const double dt = double(t_ns - last_ns_) * kSecondsPerNanosecond;
    bias_.x() = gauss_markov_step(bias_.x(), dt, config_.bias_sigma_m, config_.bias_tau_s, n_bias_e);
    bias_.y() = gauss_markov_step(bias_.y(), dt, config_.bias_sigma_m, config_.bias_tau_s, n_bias_n);
    heading_bias_ =
        gauss_markov_step(heading_bias_, dt, config_.heading_bias_sigma_rad, config_.heading_bias_tau_s, n_bias_h);
  }
  last_ns_ = t_ns;

  bool outage = false;
  Eigen::Vector2d jump{0, 0};  // multipath jumps of overlapping zones add up
  for (const GpsZone& zone : config_.zones) {
    if (!zone_applies(zone, t_ns, truth)) continue;
    if (zone.kind == GpsZone::Kind::outage)
      outage = true;
    else
      jump += zone.jump_m;
  }

  GpsFix fix;
  fix.stamp_ns = t_ns;
  if (outage) {
    // No position (lat/lon/alt stay 0) and a covariance that says so.
    fix.status = GpsStatus::no_fix;
    fix.position_covariance[kEast] = fix.position_covariance[kNorth] = fix.position_covariance[kUp] = kNoFixVariance;
    fix.heading_variance = kNoFixVariance;
    return fix;
  }

  const Eigen::Vector2d white = config_.white_sigma_m * Eigen::Vector2d(n_white_e, n_white_n);
  const Eigen::Vector2d antenna =
      Eigen::Vector2d(truth.x, truth.y) + Eigen::Rotation2Dd(truth.yaw) * config_.antenna_xyz.head<2>();
  const Eigen::Vector2d measured = antenna + bias_ + white + jump;
  const Geodetic g = frame_.to_geodetic(
      measured, frame_.origin().alt_m + config_.antenna_xyz.z() + config_.vertical_sigma_m * n_white_u);
  fix.status = GpsStatus::fix;
  fix.lat_deg = g.lat_deg;
  fix.lon_deg = g.lon_deg;
  fix.alt_m = g.alt_m;
  fix.heading_rad = wrap_angle(truth.yaw + heading_bias_ + config_.heading_white_sigma_rad * n_white_h);
  // The receiver's own accuracy estimate: the stationary error variance. It knows nothing of multipath.
  const double horizontal = config_.bias_sigma_m * config_.bias_sigma_m + config_.white_sigma_m * config_.white_sigma_m;
  fix.position_covariance[kEast] = fix.position_covariance[kNorth] = horizontal;
  fix.position_covariance[kUp] = config_.vertical_sigma_m * config_.vertical_sigma_m;
  fix.heading_variance = config_.heading_bias_sigma_rad * config_.heading_bias_sigma_rad +
                         config_.heading_white_sigma_rad * config_.heading_white_sigma_rad;
  return fix;
}

int64_t GpsModel::period_ns() const { return period_for(config_.rate_hz); }

RtkModel::RtkModel(const RtkConfig& config, const LocalFrame& frame, uint64_t seed)
    : config_(config), frame_(frame), rng_(seed) {
  require(finite_positive(config.rate_hz), "RTK config: rate_hz must be positive");
  require(finite_non_negative(config.sigma_m) && finite_non_negative(config.heading_sigma_rad),
          "RTK config: noise sigmas must not be negative");
}

GpsFix RtkModel::sample(int64_t t_ns, const Pose2d& truth) {
  // Four normals per call, in this order: east, north, up, heading.
  const double n_e = normal_(rng_), n_n = normal_(rng_), n_u = normal_(rng_), n_h = normal_(rng_);
  const Eigen::Vector2d measured = Eigen::Vector2d(truth.x, truth.y) + config_.sigma_m * Eigen::Vector2d(n_e, n_n);
  const Geodetic g = frame_.to_geodetic(measured, frame_.origin().alt_m + config_.sigma_m * n_u);
  GpsFix fix;
  fix.stamp_ns = t_ns;
  fix.status = GpsStatus::rtk;
  fix.lat_deg = g.lat_deg;
  fix.lon_deg = g.lon_deg;
  fix.alt_m = g.alt_m;
  fix.heading_rad = wrap_angle(truth.yaw + config_.heading_sigma_rad * n_h);
  const double variance = config_.sigma_m * config_.sigma_m;
  fix.position_covariance[kEast] = fix.position_covariance[kNorth] = fix.position_covariance[kUp] = variance;
  fix.heading_variance = config_.heading_sigma_rad * config_.heading_sigma_rad;
  return fix;
}

int64_t RtkModel::period_ns() const { return period_for(config_.rate_hz); }

}  // namespace lidarloop
