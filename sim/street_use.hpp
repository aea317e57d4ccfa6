#pragma once
// The street as it is used: the actors a drive meets that nobody scripts one by one. Cars parked along
// the curbs at the occupancy cities manage to, pedestrians walking the sidewalks and crossing at the
// crosswalks, cyclists riding at the curb, buses stopping at their stops. A scenario's `street:` section
// says where and how many; street_actors() draws them, from the scenario's seed, as the same ActorPlans
// a scenario's `traffic:` list gives. Like those, they move along their paths whatever the ego does.
//
// Worlds described by roads (world.yaml) only: a stretch is a side of a named road between two arc
// lengths along its centreline.
#include <cstdint>
#include <string>
#include <vector>

#include "common/yaml_reader.hpp"
#include "sim/traffic.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct StreetStretch {
  std::string where;  // file:line:col of the entry, for errors
  std::string road;
  RoadSide side = RoadSide::both;
  double from = 0;  // arc length along the road's centreline, m
  double to = -1;   // m; negative: to the road's end
};

// Parallel parking along the curb: the stretches are cut into stalls, each taken with probability
// `occupancy`.
struct ParkingConfig {
  std::vector<StreetStretch> stretches;
  // Shoup, "The High Cost of Free Parking" (2005), and SFpark's pricing rule after it: curb parking
  // priced so that about one space in eight is free, 85 %; unpriced and time-limited curbs run full.
  double occupancy = 0.85;
  // Parallel stalls of 20-24 ft (6.1-7.3 m) in municipal codes and NACTO's Urban Street Design Guide:
  // their middle (an assumption within that range).
  double stall_length_m = 6.7;
  // Wheels within 18 in (0.46 m) of the curb (California Vehicle Code 22502, as most US codes); the body
  // sits about this far from the curb face (an assumption within that limit).
  double curb_gap_m = 0.3;
  // No parking within 20 ft (6.1 m) of a crosswalk or of a junction's mouth, nor in front of a driveway
  // or a curb ramp (Uniform Vehicle Code 11-1003, which state codes follow).
  double crosswalk_clearance_m = 6.1;
  // Of the parked vehicles, the share that are vans and small trucks (an assumption: a residential and
  // campus street is mostly cars); the rest are cars.
  double truck_share = 0.05;
};

// Pedestrians walking along the sidewalks, either way, near the curb.
struct SidewalkPedestrianConfig {
  std::vector<StreetStretch> stretches;
  double per_100m = 0;  // on each side of each stretch; set by the scenario (no single source fits a street)
  // Knoblauch, Pietrucha and Nitzburg, TRR 1538 (1996): mean walking speeds 1.51 m/s (under 65) and
  // 1.25 m/s (65 and over); their middle. The spread is an assumption: wide enough to cover both groups.
  double speed_mps = 1.38;
  double speed_sigma_mps = 0.2;
  double from_curb_m = 1.0;  // behind the curb line, m (an assumption: the sidewalk's kerbside half)
};

// Pedestrians crossing at the world's crosswalks: arrivals at each crosswalk as a Poisson process. Each
// waits on the sidewalk beside the crosswalk until its time, crosses, and walks on along the far side.
struct CrossingPedestrianConfig {
  std::string where;            // file:line:col of the section, for errors
  double per_minute = 0;        // at each crosswalk, both directions together; set by the scenario
  std::vector<int> crosswalks;  // the world's crosswalk numbers; empty: every crosswalk
  double speed_mps = 1.38;      // as SidewalkPedestrianConfig
  double speed_sigma_mps = 0.2;
  // How far along the sidewalk a pedestrian waits before crossing and walks to after it, drawn
  // uniformly up to this (an assumption: they come from and go to the nearby buildings).
  double spread_m = 15;
};

// Cyclists riding with the traffic of their side, near the curb.
struct CyclistConfig {
  std::vector<StreetStretch> stretches;
  double per_km = 0;  // on each side of each stretch; set by the scenario
  // El-Geneidy, Krizek and Iacono (2007), Minneapolis GPS traces: mean commuting speed about 16 km/h.
  // The spread between riders is an assumption (about 3 km/h).
  double speed_mps = 4.5;
  double speed_sigma_mps = 0.8;
  // The cyclist's centre from the curb face (an assumption: riders keep 0.5-1 m off the curb, as
  // AASHTO's Guide for the Development of Bicycle Facilities allows for in a shared lane).
  double from_curb_m = 0.8;
};

// A bus that drives up its lane, pulls in to stand at the stop with its door side at the curb, and
// pulls out to drive on. No one parks in the bus zone: the bus's length and its pull-in and pull-out.
struct BusStopSpec {
  std::string where, road;
  RoadSide side = RoadSide::right;  // the stop's side of the road; the bus travels with that side's traffic
  double at = 0;                    // arc length of the stop along the road's centreline, m
  double arrive_s = 0;              // when the bus reaches the stop
  // TCQSM (Transit Capacity and Quality of Service Manual, 3rd ed., TCRP Report 165): dwell times of
  // 30-60 s at busy stops; the lower end for a campus stop (an assumption within that range).
  double dwell_s = 30;
  double speed_mps = 8.3;   // 30 km/h, the campus streets' design speed, m/s
  double curb_gap_m = 0.3;  // as a parked vehicle's
  // Along the road over which the bus moves between its lane and the curb, before and after the stop:
  // with the bus's 12 m, a 42 m (138 ft) zone, within the 90-150 ft curbside stops of TCRP Report 19
  // (Guidelines for the Location and Design of Bus Stops).
  double pull_in_m = 15;
};

struct StreetUse {
  ParkingConfig parking;
  SidewalkPedestrianConfig sidewalk_pedestrians;
  CrossingPedestrianConfig crossing_pedestrians;
  CyclistConfig cyclists;
  std::vector<BusStopSpec> bus_stops;

  bool empty() const;
};

// The scenario's `street:` section; InputError names the file, line and key of a bad entry.
void read_street_use(const YamlReader& yaml, const YAML::Node& node, StreetUse& street);

// One generated actor and the scenario entry it comes from (for errors about its path).
struct StreetActor {
  ActorPlan plan;
  std::string where;
};

// The first place where a vehicle following `path` from arc length `from_s` to `to_s` (with the given
// footprint, centred on the path; unwrapped on closed paths) would drive through one of the `parked`
// actors: a description naming the place and the actor, or empty.
std::string drives_through_parked(const Path& path, double from_s, double to_s, const ActorFootprint& footprint,
                                  const std::vector<ActorPlan>& parked);

// Every actor the section asks for over a drive of `duration_s`, drawn from `seed` (the scenario's):
// the same seed gives the same actors. Names are "<type>_<first_index + k>", continuing the scenario's
// own traffic. InputError (naming the entry) for an unknown road or crosswalk, a stretch outside its
// road, or a world without roads.
std::vector<StreetActor> street_actors(const StreetUse& street, const WorldDescription& world, double duration_s,
                                       uint64_t seed, size_t first_index);

}  // namespace lidarloop
