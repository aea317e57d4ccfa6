#pragma once
// The scenario's kidnaps of the belief (`faults:`, sim/scenario.hpp's KidnapFault) as the localizer meets them:
// each moves its pose (Localizer::displace) just before the scan that starts nearest the kidnap's
// time, read from the scan's own stamp. That stamp is what the live loop, `replay` (from the log) and
// the benchmark all have, so all three kidnap before the same scan and a replay stays bit-exact.
// Scenario seconds count from the start of the run on the simulation's clock; a scan's stamp is the
// LiDAR clock's (sim/clocks.hpp): the scan's start plus the clock's offset plus a jitter of a
// millisecond or so. So the offset is taken off, and a scan is due from half a scan period before the
// kidnap's time: the scan that starts at a kidnap's time takes it whichever way the jitter went.
#include <cstdint>
#include <vector>

#include "common/pose2d.hpp"
#include "localizer/localizer_params.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

class KidnapSchedule {
 public:
  KidnapSchedule() = default;
  // The scenario's kidnaps, its LiDAR's clock offset and scan period.
  explicit KidnapSchedule(const Scenario& scenario);

  // The offsets (x forward, y left in the localizer's vehicle frame; yaw added) of the kidnaps due
  // at a scan stamped `scan_stamp_ns` and not handed out before, in order of time.
  std::vector<Pose2d> due(int64_t scan_stamp_ns);
  bool empty() const { return kidnaps_.empty(); }

 private:
  std::vector<KidnapFault> kidnaps_;  // by time
  size_t next_ = 0;                   // the first not yet handed out
  int64_t lidar_offset_ns_ = 0, scan_period_ns_ = 0;
};

// An external program's pose cannot be moved from outside (its protocol has no such message), so a
// scenario with a kidnap that moves the belief needs a built-in method: InputError naming the scenario
// otherwise. Nor can such a kidnap be faked by moving the program's world-frame inputs (the GPS) by the
// offset and its answers back: its map and its LiDAR would still agree with its belief, so it would see
// the GPS jump away from both, a GPS jump and not a kidnap. A kidnap that moves the car (`moves: car`)
// is the simulation's and reaches every method (docs/external-localizer.md, "Kidnaps").
void check_kidnaps_supported(const Scenario& scenario, const LocalizerParams& params);

}  // namespace lidarloop
