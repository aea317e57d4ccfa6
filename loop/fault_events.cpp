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
  // At the scan start the kidnap is done at, so no frame after the move counts before it.
  for (const KidnapFault& k : scenario.kidnaps) add(kidnap_scan_start_ns(k, scenario.lidar.scan_period_ns()), "kidnap");
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
