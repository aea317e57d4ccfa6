#pragma once
// The routing graph of an OpenDRIVE map, as sim/lane_graph.hpp's LaneGraph so that its routes (shortest
// routes between points, the covering routes of the mapping drive, the driven line) work unchanged.
//
// A node is a driving lane of one lane section in its direction of travel: right-hand traffic, lanes
// right of the reference line (id < 0) along s, left ones against it. Its left bound is the lane's
// inner edge, its right bound the outer edge, in the direction of travel. Edges:
// - successor: the lane it continues into in the next section (the lane's successor link, else the
//   same id), at a road's end the linked road's lane (lane links), or in a junction the connecting
//   roads' lanes its connections' laneLinks name; an edge is kept only where the one lane's end is
//   within a metre of the other's start (links that contradict the geometry are not followed);
// - left / right neighbour: the adjacent lane of the same side and section; a lane change into it is
//   allowed where the road mark between them is broken (broken, broken broken, botts dots) or absent.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sim/lane_graph.hpp"
#include "sim/opendrive_file.hpp"

namespace lidarloop {

using OdrLaneRef = std::pair<std::string, int>;  // road id, lane id

struct OdrLaneGraph {
  LaneGraph graph;                                              // LaneGraphNode::lanelet is the node's own index
  std::map<OdrLaneRef, std::vector<LaneGraphNodeId>> nodes_of;  // a lane's nodes, section by section in driving order
  std::vector<OdrLaneRef> lane_of;                              // per node
};

// step: spacing of the bounds' and centreline's samples, m.
OdrLaneGraph build_opendrive_lane_graph(const OdrMap& map, double step = 1.0);

// A scenario's `route: {opendrive: [[road, lane], ...]}`: each lane's nodes in driving order, each lane
// following the one before it (a successor of its last node, or a neighbour it may change into).
// InputError naming a lane that is not a driving lane of the map, or two lanes that do not connect.
std::vector<LaneGraphNodeId> route_from_opendrive_lanes(const OdrLaneGraph& graph,
                                                        const std::vector<OdrLaneRef>& lanes);

}  // namespace lidarloop
