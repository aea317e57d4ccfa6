#pragma once
// The routing graph on a Lanelet2 map's drivable lanelets, built the way lanelet2_routing builds its
// RoutingGraph for a vehicle (lanelet2_routing/doc/RoutingGraph.md, lanelet2_traffic_rules'
// GenericTrafficRules), and routes on it: shortest routes between two points, routes a scenario names
// lanelet by lanelet, the routes that cover every lanelet for the mapping drive, and the graph's
// connected components (issue 35: the campus export fell apart into four groups).
//
// A node is a lanelet in one driving direction. Edges:
// - successor: the node's end (last points of its left and right bounds) is the other's start
//   (Lanelet2's geometry::follows);
// - left / right neighbour: the node's left bound is the other's right bound, same direction
//   (geometry::leftOf / rightOf); a lane change into it is allowed or not by the shared bound's tags
//   (LinestringTagging.md; see lane_change_allowed below). Lanelet2 calls a neighbour one may not change
//   into "adjacent"; here it is the same neighbour with the flag off.
// Everything is planar (x, y) except point equality, which compares heights too so that a bridge does
// not join the road under it.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/curb_map_file.hpp"  // Polyline2d
#include "sim/lanelet2_file.hpp"

namespace lidarloop {

using LaneGraphNodeId = int;  // index into LaneGraph::nodes

struct LaneGraphNode {
  Lanelet2Id lanelet = 0;
  bool reversed = false;  // driven against the bounds' direction (the second node of a one_way=no lanelet)
  std::string subtype;
  // In the driving direction: bounds as the lanelet's left / right seen from the driver.
  Polyline2d centreline, left_bound, right_bound;
  double length = 0;                      // of the centreline, m
  std::optional<double> speed_limit_mps;  // the lanelet's `speed_limit` tag, if any
  std::vector<LaneGraphNodeId> successors;
  std::optional<LaneGraphNodeId> left, right;  // neighbours sharing the left / right bound, same direction
  bool can_change_left = false, can_change_right = false;
};

struct LaneGraph {
  std::vector<LaneGraphNode> nodes;
  std::map<Lanelet2Id, std::vector<LaneGraphNodeId>> nodes_of;  // a lanelet's nodes, forward first
  std::map<std::string, int> not_drivable;                      // skipped lanelets by subtype
};

struct LaneGraphOptions {
  // Points with different node ids are the same point within this (3-D) distance: maps drawn in JOSM
  // or exported by other tools do not always share nodes where lanes meet.
  double point_tolerance_m = 0.01;
  // Spacing of the centreline's samples when it is made from the bounds.
  double centreline_step_m = 1.0;
};

// Whether vehicles drive on lanelets of this subtype: Lanelet2's GenericTrafficRules::canPass for
// Participants::Vehicle ("" , road, highway, play_street, exit; not bicycle_lane, crosswalk, walkway,
// stairs, shared_walkway, nor emergency_lane, which is for emergency vehicles only).
bool drivable_subtype(const std::string& subtype);
// A lanelet's `participant:*` tags override its subtype (GenericTrafficRules::canPass): with any of them,
// vehicles only where `participant:vehicle` is yes. Karlsruhe's map has 17 road lanelets for bicycles
// and pedestrians only.
bool vehicles_allowed(const Lanelet2Tags& lanelet_tags);

// Whether a vehicle may cross `bound` from the side on its right (in the line's own point order) to its
// left (to_left) or the other way. As GenericTrafficRules::laneChangeType: a `lane_change` tag (yes / no)
// or `lane_change:left` / `lane_change:right` tags first; else line_thin / line_thick `dashed` both ways,
// `solid_dashed` to the left only and `dashed_solid` to the right only (the dashed half is on the side one
// crosses from), anything else (solid, solid_solid, curbstone, road_border, ...) not at all. `virtual`
// lines allow both ways (Lanelet2 allows that only into areas; lidarloop's own exports bound lanes that
// are split for junctions by virtual lines, which a car may cross).
bool lane_change_allowed(const Lanelet2LineString& bound, bool to_left);

// Nodes for the drivable lanelets and their edges. Skipped lanelets are counted in not_drivable by
// subtype, under "participant" when their participant tags keep vehicles out, "broken" when a bound
// has fewer than two points.
LaneGraph build_lane_graph(const Lanelet2Map& map, const LaneGraphOptions& options = {});

// The node of `lanelet` driven forward (reversed: against its bounds), if it is in the graph.
std::optional<LaneGraphNodeId> lane_graph_node(const LaneGraph& graph, Lanelet2Id lanelet, bool reversed = false);

struct RouteOptions {
  // Added to a route's cost at each lane change, m (lanelet2_routing's RoutingCostDistance has such a
  // lane change cost): prefers staying in lane when the lengths are close.
  double lane_change_cost_m = 20;
  // `from` and `to` farther than this from every drivable lanelet are an error, m.
  double max_snap_m = 10;
};

// Dijkstra by length from the lanelets containing `from` (else the nearest) to those containing `to`
// (else the nearest), either driving direction of a bidirectional lanelet; successors and allowed lane
// changes. The first node is where `from` is, the last where `to` is. InputError when a point is
// farther than max_snap_m from every lanelet or no route exists.
std::vector<LaneGraphNodeId> shortest_route(const LaneGraph& graph, const Eigen::Vector2d& from,
                                            const Eigen::Vector2d& to, const RouteOptions& options = {});

// A U-turn in a route: the car turns back from the end of the node before into the node after, whose
// start is where the one before ends (the same road driven the other way: a bidirectional lanelet's
// other node, or the opposite lane), on a loop beyond the lanelets' end. Maps end at their edges, and a
// test drive that is to be longer than the mapped streets turns there, as a mapping car does.
constexpr LaneGraphNodeId kUTurn = -1;

// A scenario's `route: {lanelets: [id, ...]}`: the nodes in order, each the next one's predecessor or
// a neighbour it may change into (a bidirectional lanelet's direction is the one that connects), or,
// at the indices in u_turns (a U-turn before lanelets[i]), the start of the way back: kUTurn is put
// between them. InputError naming the lanelet not in the graph, or the two lanelets that do not connect.
std::vector<LaneGraphNodeId> route_from_lanelets(const LaneGraph& graph, const std::vector<Lanelet2Id>& lanelets,
                                                 const std::vector<size_t>& u_turns = {});

struct RouteLineOptions {
  double lane_change_length = 30;  // m over which a lane change blends one lane's centre into the next
  // m: a U-turn's loop is arcs of this radius (right 60 deg, left 300 deg, right 60 deg when it comes
  // back to where it began: the "light bulb" turn), about a passenger car's smallest turning radius
  // (kerb-to-kerb turning circles of 10.5-11.5 m, e.g. VW Golf VIII 10.9 m) with room to spare.
  double u_turn_radius = 6.0;
  // Where the way back may start, seen from the end of the way out: at most max_u_turn_shift ahead or
  // behind, 0 to 2 u_turn_radius to the left, heading back within max_u_turn_angle.
  double max_u_turn_shift = 10.0;  // m
  double max_u_turn_angle = 0.5;   // rad
  // For route_driven_line: the centreline smoothed over this much arc length (m, the Gaussian's
  // standard deviation). A kink of a rad becomes a bend of curvature a / (2.5 sigma) (0.5 rad: radius
  // 7.5 m, above a car's smallest turning radius), and a bend of radius 15 m moves in by 7 cm.
  double smoothing_sigma = 1.5;
  double step = 0.5;  // m between the driven line's points
};

// The route's centrelines joined into one line. A run of lane changes (consecutive neighbours) is
// driven along the run's lanelets, each for an equal share of their length, changing lane by a smooth
// (smoothstep) transition over lane_change_length metres; a kUTurn is a loop from the end of the node
// before it to the start of the node after. InputError naming both lanelet ids when consecutive nodes
// are neither successors nor neighbours, or when the way back does not start where a U-turn can reach.
Polyline2d route_centreline(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                            const RouteLineOptions& options = {});
// The line a car drives along a route: route_centreline smoothed (sim/polyline.hpp's smooth_polyline).
// Centrelines made from a map's bounds kink where lanelets meet (lanes of different widths, a lane
// change run joining its successor: 0.6 rad within a metre on Karlsruhe's roundabout), and a path
// controller's curvature feed-forward turns each kink into a steering spike that a car at speed
// cannot follow. A driver steers through such a kink over about a car length.
Polyline2d route_driven_line(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                             const RouteLineOptions& options = {});
// Its length without building it: successors add their lengths; a run of neighbours counts once, at
// its lanelets' mean length; a U-turn adds its loop's length.
double route_length(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                    const RouteLineOptions& options = {});

// A few chains of successors that together drive every drivable lanelet at least once (one direction
// of a bidirectional one is enough), longest first: the mapping drive follows them. Greedy: a chain
// starts at an uncovered lanelet no other lanelet leads into (else any uncovered one) and goes on to the
// nearest uncovered lanelet ahead, through covered ones, while that is at most max_detour_m away.
std::vector<std::vector<LaneGraphNodeId>> covering_routes(const LaneGraph& graph, double max_detour_m = 300);

// Connected components over successor and allowed lane change edges: strong (every node reaches every
// other: a car can drive anywhere and back) and weak (edges taken both ways; neighbours join whether or
// not a lane change is allowed).
struct LaneGraphComponents {
  std::vector<int> strong_of, weak_of;        // component index per node
  std::vector<int> strong_sizes, weak_sizes;  // nodes per component, largest first
};
LaneGraphComponents lane_graph_components(const LaneGraph& graph);
// "N nodes; S strongly connected components (sizes a, b, ...); W weakly (sizes ...)", sizes truncated.
std::string describe_components(const LaneGraphComponents& components);

// Nodes reachable from `start` by successors and allowed lane changes, `start` included, sorted.
std::vector<LaneGraphNodeId> reachable_from(const LaneGraph& graph, LaneGraphNodeId start);

// "lanelet 123" or "lanelet 123 (reversed)", for messages.
std::string describe_node(const LaneGraph& graph, LaneGraphNodeId node);

}  // namespace lidarloop
