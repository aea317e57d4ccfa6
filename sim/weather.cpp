#include "sim/weather.hpp"

#include <cmath>

#include "sim/counter_rng.hpp"

namespace lidarloop {

namespace {
constexpr uint64_t kPuddleStream = 0x7075646cULL;
// A puddle is a disc of this radius (in cells) whose centre is jittered so it stays inside its cell.
constexpr double kPuddleRadius = 0.4;
constexpr double kMaxPuddleFraction = M_PI * kPuddleRadius * kPuddleRadius;  // every cell holds one
}  // namespace

WeatherConfig weather_config_for(Realism realism) {
  WeatherConfig c;
  if (realism == Realism::harsh) {
    c.wet = true;
    c.puddle_fraction = 0.05;
    c.rain_rate_mm_h = 5.0;
    c.spray = true;
  }
  return c;
}

void read_weather_config(const YamlReader& y, const YAML::Node& n, WeatherConfig& c) {
  YamlMap(y, n, "weather")
      .boolean("wet", c.wet)
      .number("wet_road_factor", c.wet_road_factor, 0.0, 1.0)
      .number("wet_marking_factor", c.wet_marking_factor, 0.0, 1.0)
      .number("puddle_fraction", c.puddle_fraction, 0.0, 0.5)
      .number("puddle_cell_m", c.puddle_cell_m, 0.1, 100.0)
      .number("rain_rate_mm_h", c.rain_rate_mm_h, 0.0, 200.0)
      .number("rain_clutter_per_mm_h", c.rain_clutter_per_mm_h, 0.0, 0.01)
      .number("rain_clutter_range_m", c.rain_clutter_range_m, 0.01, 100.0)
      .number("clutter_intensity", c.clutter_intensity, 0.0, 100.0)
      .boolean("spray", c.spray)
      .number("spray_min_speed_mps", c.spray_min_speed_mps, 0.0, 100.0)
      .number("spray_length_s", c.spray_length_s, 0.0, 10.0)
      .number("spray_offset_m", c.spray_offset_m, -10.0, 20.0)
      .number("spray_width_m", c.spray_width_m, 0.0, 10.0)
      .number("spray_height_m", c.spray_height_m, 0.0, 10.0)
      .number("spray_density_per_m", c.spray_density_per_m, 0.0, 100.0)
      .done();
  if (c.rain_rate_mm_h * c.rain_clutter_per_mm_h > 1.0) y.fail(n, "rain_rate_mm_h * rain_clutter_per_mm_h exceeds 1");
}

bool in_puddle(const WeatherConfig& c, uint64_t seed, double x, double y) {
  if (c.puddle_fraction <= 0) return false;
  const double u = x / c.puddle_cell_m, v = y / c.puddle_cell_m;
  const double fu = std::floor(u), fv = std::floor(v);
  const uint64_t cell = mix64(uint64_t(int64_t(fu))) ^ uint64_t(int64_t(fv));
  const CounterRng rng(seed, kPuddleStream);
  if (rng.uniform(4 * cell) >= c.puddle_fraction / kMaxPuddleFraction) return false;
  const double jitter = 0.5 - kPuddleRadius;
  const double cu = fu + 0.5 + jitter * (2 * rng.uniform(4 * cell + 1) - 1);
  const double cv = fv + 0.5 + jitter * (2 * rng.uniform(4 * cell + 2) - 1);
  return (u - cu) * (u - cu) + (v - cv) * (v - cv) < kPuddleRadius * kPuddleRadius;
}

}  // namespace lidarloop
