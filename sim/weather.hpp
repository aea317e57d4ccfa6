#pragma once
// The weather a scan is taken in (scenario section `weather:`): a wet road, puddles, rain and spray.
//
// Keys (defaults = `typical`, a dry day; `harsh` = rain):
//   wet                  bool   false  the road is wet: road and marking reflectivities fall
//   wet_road_factor      0..1   0.5    reflectivity factor of wet asphalt, sidewalk and curb concrete
//   wet_marking_factor   0..1   0.3    reflectivity factor of wet lane and crosswalk paint
//   puddle_fraction      0..0.5 0      share of the carriageway (asphalt, paint) under standing water
//   puddle_cell_m        m      2.0    puddles: at most one disc of 0.8 cell diameter per cell
//   rain_rate_mm_h       mm/h   0      rain: spurious near returns from drops
//   rain_clutter_per_mm_h       1e-4   probability per firing and mm/h of a return from a drop
//   rain_clutter_range_m m      3.0    mean distance of those returns beyond the minimum range
//   clutter_intensity    counts 5      drop and spray returns read 0..this
//   spray                bool   false  moving vehicles throw spray behind them (needs a wet road)
//   spray_min_speed_mps  m/s    5.0    slower actors throw none
//   spray_length_s       s      0.4    the spray trails length = speed * this behind the vehicle
//   spray_offset_m       m      2.5    where the spray starts behind an actor's origin
//   spray_width_m, spray_height_m      2.0, 1.2
//   spray_density_per_m  1/m    0.3    returns per metre of beam path through spray at 20 m/s,
//                                      in proportion to speed below that
// Puddles are keyed by the scan seed (constant through a run), so they stay put from scan to scan.
#include <cstdint>

#include "common/yaml_reader.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

struct WeatherConfig {
  bool wet = false;
  // Wet asphalt reads darker than dry (Shin, Park & Kim 2019, J. Sensors 8973248: dry and wet asphalt
  // fall in distinguishable intensity ranges; no ratio given): factor 0.5 is an assumption.
  double wet_road_factor = 0.5;
  // Bead-reflectorised paint loses most of its return when wet (Park et al. 2023, Sensors 23:5815;
  // Burghardt et al. 2023: flat-line markings' LiDAR response dropped to nil when wetted): 0.3 is an
  // assumption between those.
  double wet_marking_factor = 0.3;
  // Standing water is a mirror: a beam that meets it glances off and nothing comes back.
  double puddle_fraction = 0;  // harsh: 0.05, assumption
  double puddle_cell_m = 2.0;  // assumption: puddles of about 1.6 m across
  // Rain: 1e-4 per firing and mm/h, i.e. 1e-3 at 10 mm/h: assumption (no measured rate found; Blainder
  // and CARLA simulate rain without one).
  double rain_rate_mm_h = 0;  // harsh: 5 mm/h, moderate rain (AMS glossary: 2.6-7.6 mm/h)
  double rain_clutter_per_mm_h = 1e-4;
  double rain_clutter_range_m = 3.0;  // assumption: only drops close to the lens echo strongly enough
  double clutter_intensity = 5;       // assumption: drops and spray are faint
  // Spray behind moving vehicles on a wet road (simulated in CARLA by arXiv 2312.12772; no magnitudes
  // found): every value here is an assumption.
  bool spray = false;
  double spray_min_speed_mps = 5.0;
  double spray_length_s = 0.4;
  double spray_offset_m = 2.5;
  double spray_width_m = 2.0;
  double spray_height_m = 1.2;
  double spray_density_per_m = 0.3;
  static constexpr double kSprayFullSpeedMps = 20.0;

  bool dry() const { return !wet && puddle_fraction == 0 && rain_rate_mm_h == 0 && !spray; }
};

// ideal and typical: a dry day; harsh: rain on a wet road with puddles and spray.
WeatherConfig weather_config_for(Realism realism);

// Applies the overrides in a YAML mapping (keys as the field names) and validates the result.
void read_weather_config(const YamlReader& yaml, const YAML::Node& node, WeatherConfig& config);

// Whether the carriageway at (x, y) in the world lies under a puddle, for puddles keyed by `seed`.
bool in_puddle(const WeatherConfig& config, uint64_t seed, double x, double y);

}  // namespace lidarloop
