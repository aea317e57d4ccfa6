#pragma once
// Realism profiles (scenario key `realism`): one word that selects sourced defaults for every realism
// knob of the world, the map, the body and the sensor; any knob can still be overridden in its own
// section of the scenario (`lidar`, `body`, `weather`, `clocks`, ...).
//   ideal    the simulator before realism: flat ground, ideal curbs, a map that is the world, a rigid
//            body, the nominal mount, synchronous clocks, a dry day, and the HDL-32E as it was (range
//            noise and its unit's per-laser gains, but no per-laser range biases or intensity offsets,
//            no mixed returns) (for debugging and unit tests);
//   typical  a well-kept campus on a dry day, a survey-grade map, a factory-calibrated sensor;
//   harsh    a worn map, rain, a poorly calibrated sensor.
// Each knob's config struct has the `typical` values as its defaults, with their sources beside them,
// and a `*_for(Realism)` function that gives the other two.
#include <optional>
#include <string>
#include <string_view>

namespace lidarloop {

enum class Realism { ideal, typical, harsh };

inline const char* realism_name(Realism r) {
  switch (r) {
    case Realism::ideal:
      return "ideal";
    case Realism::typical:
      return "typical";
    case Realism::harsh:
      return "harsh";
  }
  return "typical";
}

inline std::optional<Realism> parse_realism(std::string_view word) {
  for (Realism r : {Realism::ideal, Realism::typical, Realism::harsh})
    if (word == realism_name(r)) return r;
  return std::nullopt;
}

}  // namespace lidarloop
