#pragma once
// The vehicle's CAN bus: wheel speeds and steering-wheel angle as a production car reports them
// (frame layout in assets/vehicle_can.dbc): quantised, noisy, with a scale-factor error (tyre radius),
// a steering offset, bus latency and dropped frames. The host stamps a frame on arrival with its own
// clock (sim/clocks.hpp): the stamp is the arrival time plus that clock's offset and jitter.
#include <array>
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "common/vehicle_messages.hpp"
#include "sim/clocks.hpp"

namespace lidarloop {

struct CanConfig {
  double rate_hz = 100.0;
  double wheel_speed_resolution_mps = 0.01;  // quantisation step
  double wheel_speed_noise_mps = 0.02;       // 1 sigma, white
  double wheel_speed_scale_error = 0.005;    // reported = true * (1 + this): tyre radius error
  double min_detectable_speed_mps = 0.1;     // below this a wheel reads 0 (too few encoder pulses)
  double steering_resolution_rad = 0.0017;   // ~0.1 deg at the steering wheel
  double steering_noise_rad = 0.002;         // 1 sigma at the steering wheel
  double steering_offset_rad = 0.0;          // constant bias at the steering wheel
  int64_t latency_ns = 10'000'000;           // measurement to arrival
  double dropout_probability = 0.0;          // per frame
};

class CanModel {
 public:
  // `clock`: the host clock that stamps the frames (default: the reference clock itself).
  CanModel(const CanConfig& config, uint64_t seed, const StampClock& clock = {});
  // Measures the truth at time t (call at the configured rate, in increasing time); the frame
  // arrives latency_ns later unless dropped, stamped by the clock.
  void measure(int64_t t_ns, const std::array<double, 4>& wheel_speeds_mps, double steering_wheel_angle_rad);
  // Frames that have arrived by `now`, oldest first; each is returned once.
  std::vector<CanFrame> deliver(int64_t now_ns);
  int64_t period_ns() const;

 private:
  CanConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  StampClock clock_;
  CounterRng clock_rng_;  // the clock's jitter, by frame index: apart from the noise draws above
  uint64_t frame_index_ = 0;
  struct InFlight {
    int64_t arrival_ns;  // reference clock
    CanFrame frame;      // stamped by the host clock
  };
  std::deque<InFlight> in_flight_;
};

}  // namespace lidarloop
