#pragma once
// How much of the curb the traffic hid from the LiDAR in one scan, measured by the simulator
// (sim/curb_visibility.hpp) from the true scene: the occlusion a run actually had, for plotting
// localization error against it.
#include <cstdint>

namespace lidarloop {

struct CurbVisibility {
  int64_t stamp_ns = 0;  // the scan's start on the reference clock (as the truth's stamps)
  int visible = 0;       // curb samples in range the LiDAR sees
  int hidden = 0;        // in range, seen without the traffic, but an actor is in the way
  // In range but out of sight of the static world alone (a building, the terrain, the curb's own
  // corner): not the traffic's doing, so in neither count above.
  int blocked_by_world = 0;
};

}  // namespace lidarloop
