#include "sim/can_model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lidarloop {
namespace {

constexpr double kNanosecondsPerSecond = 1e9;
constexpr uint64_t kClockStream = 0x63616e636c6f636b;  // "canclock": the stamping clock's jitter

// Rounds to the nearest multiple of `resolution`, as the ECU's integer encoding does (the factor
// in assets/vehicle_can.dbc); a resolution of 0 means the value is not quantised.
double quantise(double value, double resolution) {
  return resolution > 0 ? std::round(value / resolution) * resolution : value;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("CAN config: " + what);
}

}  // namespace

CanModel::CanModel(const CanConfig& config, uint64_t seed, const StampClock& clock)
    : config_(config), rng_(seed), clock_(clock), clock_rng_(seed, kClockStream) {
  require(std::isfinite(config.rate_hz) && config.rate_hz > 0, "rate_hz must be positive");
  require(config.wheel_speed_resolution_mps >= 0 && config.steering_resolution_rad >= 0,
          "resolutions must not be negative");
  require(config.wheel_speed_noise_mps >= 0 && config.steering_noise_rad >= 0, "noise must not be negative");
  require(config.wheel_speed_scale_error > -1, "wheel_speed_scale_error must be > -1");
  require(config.latency_ns >= 0, "latency must not be negative");
  require(config.dropout_probability >= 0 && config.dropout_probability < 1, "dropout_probability must be in [0, 1)");
  require(clock.jitter_ns >= 0, "clock jitter must not be negative");
}

void CanModel::measure(int64_t t_ns, const std::array<double, 4>& wheel_speeds_mps, double steering_wheel_angle_rad) {
  const int64_t arrival = t_ns + config_.latency_ns;
  // One constant latency keeps the FIFO sorted by arrival only if measurements come in time order.
  if (!in_flight_.empty() && arrival < in_flight_.back().arrival_ns)
    throw std::logic_error("CanModel::measure called with a time earlier than the previous one");

  // Every call draws, in this order: the dropout uniform, four wheel-speed normals (FL, FR, RL, RR),
  // one steering normal -- whether or not the frame is dropped. So the noise of frame k depends only
  // on the seed and k: a run with dropouts delivers exactly the values of the same run without them.
  const bool dropped = uniform_(rng_) < config_.dropout_probability;
  CanFrame frame;
  // The host's stamp; jitter may put it before the previous frame's (a consumer sees it out of order).
  frame.stamp_ns = stamp_on(clock_, arrival, clock_rng_, frame_index_++);
  for (size_t i = 0; i < wheel_speeds_mps.size(); ++i) {
    // A wheel-speed sensor counts tooth pulses: it reports a magnitude, whatever the direction.
    const double scaled = std::abs(wheel_speeds_mps[i]) * (1.0 + config_.wheel_speed_scale_error);
    const double reported =
        quantise(scaled + config_.wheel_speed_noise_mps * normal_(rng_), config_.wheel_speed_resolution_mps);
    // Too few pulses per frame below the minimum speed: the sensor reads exactly 0, as at a standstill.
    const bool detectable = std::abs(wheel_speeds_mps[i]) >= config_.min_detectable_speed_mps;
    frame.wheel_speed_mps[i] = detectable && reported > 0 ? reported : 0.0;  // also turns -0.0 into 0.0
  }
  frame.steering_wheel_angle_rad =
      quantise(steering_wheel_angle_rad + config_.steering_offset_rad + config_.steering_noise_rad * normal_(rng_),
               config_.steering_resolution_rad);
  if (!dropped) in_flight_.push_back({arrival, frame});
}

std::vector<CanFrame> CanModel::deliver(int64_t now_ns) {
  std::vector<CanFrame> arrived;
  while (!in_flight_.empty() && in_flight_.front().arrival_ns <= now_ns) {
    arrived.push_back(in_flight_.front().frame);
    in_flight_.pop_front();
  }
  return arrived;
}

int64_t CanModel::period_ns() const { return std::llround(kNanosecondsPerSecond / config_.rate_hz); }

}  // namespace lidarloop
