#include "loop/fault_events.hpp"

#include <algorithm>
#include <cmath>

#include "common/units.hpp"

namespace lidarloop {

std::vector<FaultEvent> fault_events(const Scenario& scenario, int64_t start_ns) {
  std::vector<FaultEvent> events{{start_ns, "start"}};
  auto add = [&](int64_t stamp_ns, const char* what) {
    if (stamp_ns > start_ns && stamp_ns < scenario.duration_ns()) events.push_back({stamp_ns, what});
  };
  // A kidnap is done at the scan start nearest its time, from half a scan period before it (as
  // loop/kidnap_schedule.hpp and the simulation do it): the event is then, so no frame after the move
  // counts before it.
  const int64_t period = scenario.lidar.scan_period_ns();
  for (const KidnapFault& k : scenario.kidnaps) {
    const int64_t due_from = std::llround(k.at_s * double(kNsPerS)) - period / 2;
    const int64_t scans = due_from <= 0 ? 0 : (due_from + period - 1) / period;  // the first scan start >= due_from
    add(scans * period, "kidnap");
  }
  for (const GpsZone& z : scenario.gps.zones) {
    if (z.kind != GpsZone::Kind::multipath || z.radius_m > 0) continue;
    add(z.from_ns, "gps jump");
    add(z.to_ns, "gps jump back");
  }
  // Stable: the start stays first among events at its stamp, the rest keep the scenario's order.
  std::stable_sort(events.begin(), events.end(),
                   [](const FaultEvent& a, const FaultEvent& b) { return a.stamp_ns < b.stamp_ns; });
  return events;
}

}  // namespace lidarloop
