#pragma once
// An OpenDRIVE map's driving lanes as paths a car drives: each lane's centreline in its direction of
// travel (right-hand traffic: lanes right of the reference line along s, left ones against it), for
// the default start pose and the mapping drive until routes through junctions are built.
#include <vector>

#include "common/curb_map_file.hpp"  // Polyline2d
#include "sim/opendrive_file.hpp"

namespace lidarloop {

struct OdrLanePath {
  std::string road;
  int lane = 0;  // the lane's id in the road's first section it is in
  Polyline2d centreline;
};

// Every driving lane of every road outside junctions, one path per lane per run of sections in which
// a lane of that id drives, sampled every `step` metres; longest first.
std::vector<OdrLanePath> opendrive_driving_paths(const OdrMap& map, double step = 0.5);

}  // namespace lidarloop
