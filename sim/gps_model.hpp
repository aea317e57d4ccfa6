#pragma once
// A low-cost GPS receiver (the paper's: ~2 m RMSE per axis, 1.5-2 deg heading error) and an RTK-like
// ground-truth receiver (~3 cm).
//
// Position error per axis = first-order Gauss-Markov bias + white noise. The bias is propagated with
// the exact discretisation  b <- e^{-dt/tau} b + sigma sqrt(1 - e^{-2 dt/tau}) n,  so its stationary
// standard deviation is sigma and its correlation time tau at any sample rate. Heading error is the
// same kind of process. Zones (in space or time) make the receiver lose its fix or jump (multipath).
// The fix is the antenna's position, `antenna_xyz` from the rear axle in the vehicle frame (the lever
// arm); the localizer is told the nominal lever arm and takes it off (sim/sensor_calibration.hpp draws
// how far the true antenna is from the nominal).
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"
#include "common/vehicle_messages.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

struct GpsZone {
  enum class Kind { outage, multipath };
  Kind kind = Kind::outage;
  // Where: a circle in the local frame (radius > 0), and/or a time window; both must hold when both are set.
  Eigen::Vector2d centre{0, 0};
  double radius_m = 0;  // 0: everywhere
  int64_t from_ns = 0, to_ns = INT64_MAX;
  Eigen::Vector2d jump_m{0, 0};  // multipath: added to the position (east, north)
};

struct GpsConfig {
  double rate_hz = 10.0;
  double bias_sigma_m = 2.0;              // per horizontal axis, stationary 1 sigma
  double bias_tau_s = 120.0;              // correlation time
  double white_sigma_m = 0.4;             // per horizontal axis
  double vertical_sigma_m = 3.0;          // white, on altitude
  double heading_bias_sigma_rad = 0.026;  // ~1.5 deg
  double heading_bias_tau_s = 60.0;
  double heading_white_sigma_rad = 0.017;
  // The antenna in the vehicle frame (x forward, y left, z up from the rear axle centre on the ground):
  // on the roof's centre line, 0.9 m ahead of the rear axle, 1.5 m up (assumption: a sedan's roof,
  // behind the LiDAR at 1.2 m). ideal: at the rear axle (no lever arm).
  Eigen::Vector3d antenna_xyz{0.9, 0.0, 1.5};
  std::vector<GpsZone> zones;
};
// ideal: the antenna at the rear axle; typical and harsh: the defaults (the noise figures are the
// paper's receiver under every profile).
GpsConfig gps_config_for(Realism realism);

class GpsModel {
 public:
  GpsModel(const GpsConfig& config, const LocalFrame& frame, uint64_t seed);
  // A fix of the antenna on a car whose rear axle is at `truth` at time t (call in increasing time at the configured
  // rate); status no_fix inside an outage zone (and no position then).
  GpsFix sample(int64_t t_ns, const Pose2d& truth);
  int64_t period_ns() const;

 private:
  GpsConfig config_;
  LocalFrame frame_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Vector2d bias_{0, 0};
  double heading_bias_ = 0;
  int64_t last_ns_ = -1;
};

struct RtkConfig {
  double rate_hz = 10.0;
  double sigma_m = 0.03;
  double heading_sigma_rad = 0.002;
};

// Ground truth as an RTK receiver reports it: white noise only, always fixed.
class RtkModel {
 public:
  RtkModel(const RtkConfig& config, const LocalFrame& frame, uint64_t seed);
  GpsFix sample(int64_t t_ns, const Pose2d& truth);
  int64_t period_ns() const;

 private:
  RtkConfig config_;
  LocalFrame frame_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace lidarloop
