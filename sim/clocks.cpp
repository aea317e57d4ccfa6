#include "sim/clocks.hpp"

#include <cmath>

namespace lidarloop {
namespace {

constexpr double kNsPerMs = 1e6;
constexpr double kMaxOffsetMs = 1000, kMaxJitterMs = 100;
constexpr int64_t kHarshLidarOffsetNs = 20'000'000;  // ros-drivers/velodyne PR #88: "in the range of 20ms"
constexpr int64_t kHarshJitterNs = 6'700'000;        // issue #386's "up to 20 ms" as 3 sigma (assumption)

void read_ms(YamlMap& m, const char* key, int64_t& ns, double lo, double hi) {
  double ms = double(ns) / kNsPerMs;
  m.number(key, ms, lo, hi);
  ns = std::llround(ms * kNsPerMs);
}

}  // namespace

ClockConfig clock_config_for(Realism realism) {
  ClockConfig c;
  switch (realism) {
    case Realism::ideal:
      c.lidar = c.can = StampClock{};
      break;
    case Realism::typical:
      break;
    case Realism::harsh:
      c.lidar = {kHarshLidarOffsetNs, kHarshJitterNs};
      c.can = {0, kHarshJitterNs};
      break;
  }
  return c;
}

void read_clocks(const YamlReader& y, const YAML::Node& node, ClockConfig& c) {
  YamlMap m(y, node, "clocks");
  read_ms(m, "lidar_offset_ms", c.lidar.offset_ns, -kMaxOffsetMs, kMaxOffsetMs);
  read_ms(m, "lidar_jitter_ms", c.lidar.jitter_ns, 0.0, kMaxJitterMs);
  read_ms(m, "can_offset_ms", c.can.offset_ns, -kMaxOffsetMs, kMaxOffsetMs);
  read_ms(m, "can_jitter_ms", c.can.jitter_ns, 0.0, kMaxJitterMs);
  m.done();
}

int64_t stamp_on(const StampClock& clock, int64_t t_ns, const CounterRng& rng, uint64_t index) {
  if (clock.jitter_ns == 0) return t_ns + clock.offset_ns;  // no draw: synchronous clocks stay exact
  return t_ns + clock.offset_ns + std::llround(double(clock.jitter_ns) * rng.normal(index));
}

}  // namespace lidarloop
