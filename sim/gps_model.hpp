#pragma once
// A low-cost GPS receiver (the paper's: ~2 m RMSE per axis, 1.5-2 deg heading error) and an RTK-like
// ground-truth receiver (~3 cm).
//
// Position error per axis = first-order Gauss-Markov bias + white noise. The bias is propagated with
// the exact discretisation  b <- e^{-dt/tau} b + sigma sqrt(1 - e^{-2 dt/tau}) n,  so its stationary
// standard deviation is sigma and its correlation time tau at any sample rate. Heading error is the
// same kind of process. Zones (in space or time) make the receiver lose its fix or jump (multipath).
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"
#include "common/vehicle_messages.hpp"

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
  std::vector<GpsZone> zones;
};

class GpsModel {
 public:
  GpsModel(const GpsConfig& config, const LocalFrame& frame, uint64_t seed);
  // A fix of the antenna at `truth` at time t (call in increasing time at the configured rate);
  // status no_fix inside an outage zone (and no position then).
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
