#include "loop/kidnap_schedule.hpp"

#include <algorithm>
#include <cmath>

#include "common/input_error.hpp"
#include "common/units.hpp"

namespace lidarloop {

KidnapSchedule::KidnapSchedule(const Scenario& scenario)
    : lidar_offset_ns_(scenario.clocks.lidar.offset_ns), scan_period_ns_(scenario.lidar.scan_period_ns()) {
  // A kidnap that moves the car is the simulation's (sim/simulation.hpp): the scans show it.
  for (const KidnapFault& k : scenario.kidnaps)
    if (k.moves == KidnapMoves::belief) kidnaps_.push_back(k);
  // Stable: two kidnaps at the same time are done in the scenario's order.
  std::stable_sort(kidnaps_.begin(), kidnaps_.end(),
                   [](const KidnapFault& a, const KidnapFault& b) { return a.at_s < b.at_s; });
}

std::vector<Pose2d> KidnapSchedule::due(int64_t scan_stamp_ns) {
  const int64_t scan_start_ns = scan_stamp_ns - lidar_offset_ns_;  // on the simulation's clock, give or take the jitter
  std::vector<Pose2d> out;
  for (; next_ < kidnaps_.size(); ++next_) {
    const KidnapFault& k = kidnaps_[next_];
    if (std::llround(k.at_s * double(kNsPerS)) - scan_period_ns_ / 2 > scan_start_ns) break;
    out.push_back({k.offset_m.x(), k.offset_m.y(), k.yaw_rad});
  }
  return out;
}

void check_kidnaps_supported(const Scenario& scenario, const LocalizerParams& params) {
  const bool moves_a_belief = std::any_of(scenario.kidnaps.begin(), scenario.kidnaps.end(),
                                          [](const KidnapFault& k) { return k.moves == KidnapMoves::belief; });
  if (moves_a_belief && !params.external.command.empty())
    throw InputError(scenario.file + ": faults: a kidnap that moves the belief needs a built-in localizer method (" +
                     method_label(params) +
                     " is an external program, whose belief lidarloop cannot move; `moves: car` kidnaps the car "
                     "instead, which every method meets: see docs/external-localizer.md)");
}

}  // namespace lidarloop
