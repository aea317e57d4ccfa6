#pragma once
// The moments of a run a localizer must recover from (scoring/scorer.hpp's FaultEvent), from its scenario:
// the start, each kidnap (`faults:`) and each GPS jump (a multipath zone of `gps.zones`, entered and left).
#include <cstdint>
#include <vector>

#include "scoring/scorer.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

// Stamps are the simulation's clock, the one the truth, the logs and the estimates are stamped on: the
// scenario's t = 0 s is stamp 0 (sim/simulation.cpp starts its clock at 0 and records the first truth
// sample one truth period later), so a fault at `at_s` is at stamp at_s * 1e9.
//   "start"     at `start_ns`, the run's first truth stamp (the localizer's cold start)
//   "kidnap"    at the scan start each kidnap is done at, the nearest its at_s
//   "gps jump"  at each multipath zone's from_s, and "gps jump back" at its to_s, when the fix returns
//               to the truth (a localizer that held the map's pose through the jump has nothing to be
//               lost about then: the scorer asks it only to stay converged); only zones in time alone:
//               a zone with a radius jumps where the car enters it, which the scenario does not say (it
//               needs the drive), so it gives no event here.
// Sorted by stamp (ties in the order above); events before `start_ns` are dropped (a zone from 0 s is
// in force at the start, and the cold start is its event), as are zone ends at or beyond the scenario's
// duration (the fix never jumps back within the run).
std::vector<FaultEvent> fault_events(const Scenario& scenario, int64_t start_ns);

}  // namespace lidarloop
