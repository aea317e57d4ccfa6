#pragma once
// The clocks that stamp the LiDAR's scans and the CAN frames, against the reference clock (the
// simulation's, which GPS time and the ground truth keep): a constant offset and a per-message jitter
// (scenario section `clocks`). A stamp is the reference time of the event plus offset plus jitter
// (1 sigma, a near-normal draw bounded at 3.5 sigma, from the sensor's own stream keyed by the message
// index, so a run is the same at any thread count). The event of a scan is its first firing (its
// points' time offsets stay relative to the stamp); that of a CAN frame its arrival (can.latency_ms
// already puts the stamp that long after the measurement). Positive offsets stamp late.
//
// Keys (ms; `typical` defaults):
//   lidar_offset_ms  0    a driver that compensates the host's constant stamping latency (~20 ms in
//                         ros-drivers/velodyne PR #88, compensated by its time_offset, PR #89)
//   lidar_jitter_ms  1    assumption: what is left of the host's receive-time jitter after that
//   can_offset_ms    0    the CAN stamp's lag is can.latency_ms (10 ms), not counted twice
//   can_jitter_ms    2    assumption (the realism notes' suggestion): host stamping of bus frames
// ideal: all zero (synchronous clocks). harsh: an uncompensated host stamp, lidar_offset_ms 20 (PR #88's
// "in the range of 20ms"), and jitter of "up to 20 ms" between messages (ros-drivers/velodyne issue
// #386) read as a 3-sigma tail: 6.7 ms on both the LiDAR and the CAN (assumption).
#include <cstdint>

#include "common/yaml_reader.hpp"
#include "sim/counter_rng.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

struct StampClock {
  int64_t offset_ns = 0;
  int64_t jitter_ns = 0;  // 1 sigma
};

struct ClockConfig {
  StampClock lidar{0, 1'000'000};
  StampClock can{0, 2'000'000};
};

ClockConfig clock_config_for(Realism realism);
// Overrides from a `clocks:` mapping; unknown keys and bad values are file:line:col errors.
void read_clocks(const YamlReader& y, const YAML::Node& node, ClockConfig& config);

// The stamp `clock` writes for an event at reference time `t_ns`: message `index` of the stream `rng`.
int64_t stamp_on(const StampClock& clock, int64_t t_ns, const CounterRng& rng, uint64_t index);

}  // namespace lidarloop
