// The routing graph on Lanelet2 lanelets. Known truth on small maps built in code: a chain's
// successors and length, lane changes by the shared bound's line type (Lanelet2's LinestringTagging.md),
// a T junction's turns, a bidirectional lanelet's two nodes, the covering routes; and the real
// Karlsruhe map (issue 35) when ../shared/data holds it.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/lane_graph.hpp"
#include "sim/lanelet2_file.hpp"
#include "sim/path.hpp"
#include "sim/polyline.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {
namespace {

// Builds a Lanelet2Map as the reader would: points that coincide (to the millimetre) share a node id,
// so lanelets drawn from the same coordinates are joined the way a map editor joins them.
struct MapBuilder {
  Lanelet2Map map;
  std::map<std::pair<long long, long long>, Lanelet2Id> point_ids;
  Lanelet2Id next_point = 1, next_line = 1000;
  bool share_points = true;

  Lanelet2Id point_id(const Eigen::Vector2d& p) {
    if (!share_points) return next_point++;
    const auto key = std::make_pair(std::llround(p.x() * 1000), std::llround(p.y() * 1000));
    const auto it = point_ids.find(key);
    return it != point_ids.end() ? it->second : (point_ids[key] = next_point++);
  }
  Lanelet2Id line(const Polyline2d& points, const std::string& type = "line_thin", const std::string& subtype = "solid",
                  const Lanelet2Tags& extra = {}) {
    Lanelet2LineString l;
    l.id = next_line++;
    l.type = type;
    l.subtype = subtype;
    l.tags = extra;
    l.tags["type"] = type;
    if (!subtype.empty()) l.tags["subtype"] = subtype;
    for (const auto& p : points) {
      l.point_ids.push_back(point_id(p));
      l.points.emplace_back(p.x(), p.y(), 0.0);
    }
    map.lines[l.id] = l;
    return l.id;
  }
  // A lanelet on two lines; `*_inverted`: the line runs against the lanelet.
  void lanelet(Lanelet2Id id, Lanelet2Id left, Lanelet2Id right, bool left_inverted = false,
               bool right_inverted = false, const std::string& subtype = "road", bool one_way = true) {
    Lanelet2Lanelet ll;
    ll.id = id;
    ll.subtype = subtype;
    ll.left = left;
    ll.right = right;
    ll.left_points = map.lines.at(left).points;
    ll.right_points = map.lines.at(right).points;
    if (left_inverted) std::reverse(ll.left_points.begin(), ll.left_points.end());
    if (right_inverted) std::reverse(ll.right_points.begin(), ll.right_points.end());
    ll.left_inverted = left_inverted;
    ll.right_inverted = right_inverted;
    ll.one_way = one_way;
    map.lanelets.push_back(ll);
  }
};

Polyline2d straight(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y1}}; }

Polyline2d arc(const Eigen::Vector2d& centre, double radius, double from_deg, double to_deg) {
  Polyline2d out;
  const int steps = 16;
  for (int i = 0; i <= steps; ++i) {
    const double a = (from_deg + (to_deg - from_deg) * i / steps) * std::numbers::pi / 180;
    out.push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return out;
}

std::vector<Lanelet2Id> lanelets_of(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route) {
  std::vector<Lanelet2Id> out;
  for (LaneGraphNodeId n : route) out.push_back(graph.nodes[n].lanelet);
  return out;
}

LaneGraphNodeId node_of(const LaneGraph& graph, Lanelet2Id lanelet) {
  const auto n = lane_graph_node(graph, lanelet);
  EXPECT_TRUE(n) << "lanelet " << lanelet << " has no node";
  return n.value_or(0);
}

// Three eastbound lanelets of 10, 20 and 30 m, 3.5 m wide.
MapBuilder chain_map() {
  MapBuilder b;
  const double xs[] = {0, 10, 30, 60};
  for (int i = 0; i < 3; ++i)
    b.lanelet(i + 1, b.line(straight(xs[i], 0, xs[i + 1], 0)), b.line(straight(xs[i], -3.5, xs[i + 1], -3.5)));
  return b;
}

TEST(LaneGraph, StraightChainHasSuccessorsAndRouteLengthIsTheSum) {
  const LaneGraph graph = build_lane_graph(chain_map().map);
  ASSERT_EQ(graph.nodes.size(), 3u);
  EXPECT_EQ(graph.nodes[node_of(graph, 1)].successors, std::vector<LaneGraphNodeId>{node_of(graph, 2)});
  EXPECT_EQ(graph.nodes[node_of(graph, 2)].successors, std::vector<LaneGraphNodeId>{node_of(graph, 3)});
  EXPECT_TRUE(graph.nodes[node_of(graph, 3)].successors.empty());
  EXPECT_NEAR(graph.nodes[node_of(graph, 2)].length, 20, 1e-9);
  for (const auto& p : graph.nodes[node_of(graph, 2)].centreline) EXPECT_NEAR(p.y(), -1.75, 1e-9);

  const auto route = shortest_route(graph, {1, -1.75}, {59, -1.75});
  EXPECT_EQ(lanelets_of(graph, route), (std::vector<Lanelet2Id>{1, 2, 3}));
  EXPECT_NEAR(route_length(graph, route), 10 + 20 + 30, 1e-9);
  EXPECT_NEAR(polyline_length(route_centreline(graph, route)), 60, 1e-6);
  EXPECT_EQ(reachable_from(graph, node_of(graph, 2)).size(), 2u);
}

TEST(LaneGraph, EndsWithinOneCentimetreFollowWithoutSharedNodes) {
  for (const double gap : {0.005, 0.05}) {
    MapBuilder b;
    b.share_points = false;  // as a map whose lanes were drawn separately
    b.lanelet(1, b.line(straight(0, 0, 10, 0)), b.line(straight(0, -3.5, 10, -3.5)));
    b.lanelet(2, b.line(straight(10 + gap, 0, 20, 0)), b.line(straight(10 + gap, -3.5, 20, -3.5)));
    const LaneGraph graph = build_lane_graph(b.map);
    EXPECT_EQ(graph.nodes[node_of(graph, 1)].successors.size(), gap < 0.01 ? 1u : 0u) << "gap " << gap;
  }
}

// Two eastbound lanes, right (1) and left (2), sharing the line y = 0 of the given type, drawn eastward
// or westward (then both lanelets hold it inverted).
LaneGraph parallel_lanes(const std::string& type, const std::string& subtype, bool drawn_westward,
                         const Lanelet2Tags& tags = {}) {
  MapBuilder b;
  const Lanelet2Id shared =
      b.line(drawn_westward ? straight(100, 0, 0, 0) : straight(0, 0, 100, 0), type, subtype, tags);
  b.lanelet(1, shared, b.line(straight(0, -3.5, 100, -3.5)), drawn_westward);
  b.lanelet(2, b.line(straight(0, 3.5, 100, 3.5)), shared, false, drawn_westward);
  return build_lane_graph(b.map);
}

TEST(LaneGraph, LaneChangesFollowTheSharedBoundsLineType) {
  struct Case {
    std::string type, subtype;
    bool westward;
    Lanelet2Tags tags;
    bool right_to_left, left_to_right;
  };
  const Case cases[] = {
      {"line_thin", "dashed", false, {}, true, true},
      {"line_thick", "dashed", true, {}, true, true},
      {"line_thin", "solid", false, {}, false, false},
      {"line_thin", "solid_solid", false, {}, false, false},
      // The dashed half is on the line's right (in its point order): crossing from there to its left.
      {"line_thin", "solid_dashed", false, {}, true, false},
      {"line_thin", "solid_dashed", true, {}, false, true},
      {"line_thin", "dashed_solid", false, {}, false, true},
      {"line_thin", "dashed_solid", true, {}, true, false},
      {"virtual", "", false, {}, true, true},
      {"curbstone", "low", false, {}, false, false},
      // Explicit tags win over the type (GenericTrafficRules' getHardcodedChangeType).
      {"line_thin", "dashed", false, {{"lane_change", "no"}}, false, false},
      {"line_thin", "solid", false, {{"lane_change", "yes"}}, true, true},
      {"line_thin", "solid", false, {{"lane_change:left", "yes"}}, true, false},
  };
  for (const Case& c : cases) {
    const std::string what = c.type + " " + c.subtype + (c.westward ? " drawn westward" : "") +
                             (c.tags.empty() ? "" : " " + c.tags.begin()->first + "=" + c.tags.begin()->second);
    const LaneGraph graph = parallel_lanes(c.type, c.subtype, c.westward, c.tags);
    const LaneGraphNode &right = graph.nodes[node_of(graph, 1)], &left = graph.nodes[node_of(graph, 2)];
    ASSERT_EQ(right.left, node_of(graph, 2)) << what << ": not neighbours";
    ASSERT_EQ(left.right, node_of(graph, 1)) << what << ": not neighbours";
    EXPECT_FALSE(right.right || left.left) << what;
    EXPECT_EQ(right.can_change_left, c.right_to_left) << what;
    EXPECT_EQ(left.can_change_right, c.left_to_right) << what;
  }
}

TEST(LaneGraph, LanesOfOppositeDirectionsSharingABoundAreNoNeighbours) {
  MapBuilder b;
  const Lanelet2Id centre = b.line(straight(0, 0, 50, 0), "line_thin", "dashed");
  b.lanelet(1, centre, b.line(straight(0, -3.5, 50, -3.5)));      // eastbound
  b.lanelet(2, centre, b.line(straight(50, 3.5, 0, 3.5)), true);  // westbound, the centre line inverted
  const LaneGraph graph = build_lane_graph(b.map);
  for (const auto& node : graph.nodes) EXPECT_FALSE(node.left || node.right) << node.lanelet;
}

TEST(LaneGraph, LaneChangeCentrelineIsASmoothTransition) {
  const LaneGraph graph = parallel_lanes("line_thin", "dashed", false);
  const auto route = route_from_lanelets(graph, {1, 2});
  const Polyline2d line = route_centreline(graph, route, {.lane_change_length = 30});
  EXPECT_NEAR(line.front().y(), -1.75, 1e-9);
  EXPECT_NEAR(line.back().y(), 1.75, 1e-9);
  EXPECT_NEAR(route_length(graph, route), 100, 1e-9);
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d& p = line[i];
    EXPECT_GE(p.y(), line[i - 1].y() - 1e-12);  // never swerves back
    if (p.x() < 34) {
      EXPECT_NEAR(p.y(), -1.75, 1e-9) << p.x();
    }
    if (p.x() > 66) {
      EXPECT_NEAR(p.y(), 1.75, 1e-9) << p.x();
    }
    // Smooth: the steepest slope of a smoothstep over 30 m across 3.5 m is 1.5 * 3.5 / 30.
    EXPECT_LE(std::abs(p.y() - line[i - 1].y()) / (p.x() - line[i - 1].x()), 1.5 * 3.5 / 30 + 1e-6);
  }
  // The lane change costs more than staying in lane: from the right lane to a point ahead in it.
  EXPECT_EQ(lanelets_of(graph, shortest_route(graph, {5, -1.75}, {95, -1.75})), std::vector<Lanelet2Id>{1});
  EXPECT_EQ(lanelets_of(graph, shortest_route(graph, {5, -1.75}, {95, 1.75})), (std::vector<Lanelet2Id>{1, 2}));
}

// A T junction: a west-east road (eastbound lanes y in [-3.5, 0], westbound [0, 3.5]) and a road to
// the south (northbound x in [0, 3.5], southbound [-3.5, 0]), arms 50 m long, the junction 20 m across
// with a turn lanelet for every movement.
//   10 / 11: west arm in (eastbound) / out; 20 / 21: east arm in (westbound) / out; 30 / 31: south arm
//   in (northbound) / out; 40, 41: straight east / west; 42: west to south (right turn); 43: south to
//   east (right); 44: east to south (left); 45: south to west (left).
MapBuilder t_junction() {
  MapBuilder b;
  const Lanelet2Id west_centre = b.line(straight(-60, 0, -10, 0), "line_thin", "dashed");
  const Lanelet2Id east_centre = b.line(straight(10, 0, 60, 0), "line_thin", "dashed");
  const Lanelet2Id south_centre = b.line(straight(0, -60, 0, -10), "line_thin", "dashed");
  b.lanelet(10, west_centre, b.line(straight(-60, -3.5, -10, -3.5)));
  b.lanelet(11, west_centre, b.line(straight(-10, 3.5, -60, 3.5)), true);
  b.lanelet(20, east_centre, b.line(straight(60, 3.5, 10, 3.5)), true);
  b.lanelet(21, east_centre, b.line(straight(10, -3.5, 60, -3.5)));
  b.lanelet(30, south_centre, b.line(straight(3.5, -60, 3.5, -10)));
  b.lanelet(31, south_centre, b.line(straight(-3.5, -10, -3.5, -60)), true);
  const Lanelet2Id junction_centre = b.line(straight(-10, 0, 10, 0), "virtual", "");
  b.lanelet(40, junction_centre, b.line(straight(-10, -3.5, 10, -3.5), "virtual", ""));
  b.lanelet(41, junction_centre, b.line(straight(10, 3.5, -10, 3.5), "virtual", ""), true);
  const Eigen::Vector2d sw(-10, -10), se(10, -10);
  b.lanelet(42, b.line(arc(sw, 10, 90, 0), "virtual", ""), b.line(arc(sw, 6.5, 90, 0), "virtual", ""));
  b.lanelet(43, b.line(arc(se, 10, 180, 90), "virtual", ""), b.line(arc(se, 6.5, 180, 90), "virtual", ""));
  b.lanelet(44, b.line(arc(se, 10, 90, 180), "virtual", ""), b.line(arc(se, 13.5, 90, 180), "virtual", ""));
  b.lanelet(45, b.line(arc(sw, 10, 0, 90), "virtual", ""), b.line(arc(sw, 13.5, 0, 90), "virtual", ""));
  return b;
}

TEST(LaneGraph, TJunctionRoutesTurnThroughTheJunction) {
  const LaneGraph graph = build_lane_graph(t_junction().map);
  ASSERT_EQ(graph.nodes.size(), 12u);
  const auto successors = [&](Lanelet2Id id) {
    std::set<Lanelet2Id> out;
    for (LaneGraphNodeId s : graph.nodes[node_of(graph, id)].successors) out.insert(graph.nodes[s].lanelet);
    return out;
  };
  EXPECT_EQ(successors(10), (std::set<Lanelet2Id>{40, 42}));
  EXPECT_EQ(successors(20), (std::set<Lanelet2Id>{41, 44}));
  EXPECT_EQ(successors(30), (std::set<Lanelet2Id>{43, 45}));
  EXPECT_EQ(successors(42), std::set<Lanelet2Id>{31});
  EXPECT_EQ(successors(45), std::set<Lanelet2Id>{11});

  const auto west_to_south = shortest_route(graph, {-40, -1.75}, {-1.75, -40});
  EXPECT_EQ(lanelets_of(graph, west_to_south), (std::vector<Lanelet2Id>{10, 42, 31}));
  // Quarter circle of the turn's centreline, radius (10 + 6.5) / 2.
  EXPECT_NEAR(route_length(graph, west_to_south), 50 + 50 + 8.25 * std::numbers::pi / 2, 0.05);
  EXPECT_EQ(lanelets_of(graph, shortest_route(graph, {1.75, -40}, {-40, 1.75})), (std::vector<Lanelet2Id>{30, 45, 11}));
  EXPECT_EQ(lanelets_of(graph, shortest_route(graph, {40, 1.75}, {-1.75, -40})), (std::vector<Lanelet2Id>{20, 44, 31}));
  EXPECT_EQ(lanelets_of(graph, shortest_route(graph, {40, 1.75}, {-40, 1.75})), (std::vector<Lanelet2Id>{20, 41, 11}));
  // The turn's centreline is continuous with the arms'.
  const Polyline2d line = route_centreline(graph, west_to_south);
  for (size_t i = 1; i < line.size(); ++i) EXPECT_LT((line[i] - line[i - 1]).norm(), 1.01);

  // Weakly one piece; the arms' outer ends lead nowhere, so not strongly.
  const LaneGraphComponents components = lane_graph_components(graph);
  EXPECT_EQ(components.weak_sizes, std::vector<int>{12});
  EXPECT_EQ(components.strong_sizes.size(), 12u) << describe_components(components);
  EXPECT_EQ(reachable_from(graph, node_of(graph, 30)).size(), 5u);  // 30, its two turns, 21 and 11
}

TEST(LaneGraph, RouteErrorsSayWhatIsWrong) {
  const LaneGraph graph = build_lane_graph(t_junction().map);
  const auto message = [&](const Eigen::Vector2d& from, const Eigen::Vector2d& to) -> std::string {
    try {
      shortest_route(graph, from, to);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message({0, 500}, {-40, -1.75}).find("from (0.0, 500.0) is"), std::string::npos)
      << message({0, 500}, {-40, -1.75});
  EXPECT_NE(message({-40, -1.75}, {300, 0}).find("m from the nearest drivable lanelet"), std::string::npos);
  // The west arm's outgoing lane leads out of the map: nothing from it reaches the east arm.
  const std::string none = message({-40, 1.75}, {40, -1.75});
  EXPECT_NE(none.find("no drivable route"), std::string::npos) << none;
  EXPECT_NE(none.find("lanelet 11"), std::string::npos) << none;
  EXPECT_NE(none.find("lanelet 21"), std::string::npos) << none;

  const LaneGraph empty = build_lane_graph(Lanelet2Map{});
  EXPECT_THROW(shortest_route(empty, {0, 0}, {1, 1}), InputError);
}

TEST(LaneGraph, RouteFromLaneletIdsChecksConnectivity) {
  const LaneGraph chain = build_lane_graph(chain_map().map);
  EXPECT_EQ(lanelets_of(chain, route_from_lanelets(chain, {1, 2, 3})), (std::vector<Lanelet2Id>{1, 2, 3}));
  const auto message = [](const LaneGraph& graph, const std::vector<Lanelet2Id>& ids) -> std::string {
    try {
      route_from_lanelets(graph, ids);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(chain, {1, 3}), "route: lanelet 3 neither follows lanelet 1 nor is beside it");
  EXPECT_EQ(message(chain, {1, 7}), "route: lanelet 7 is not a drivable lanelet of the map");
  const LaneGraph solid = parallel_lanes("line_thin", "solid", false);
  EXPECT_EQ(message(solid, {1, 2}),
            "route: lanelet 2 is beside lanelet 1 but their shared bound forbids a lane change");
  // route_centreline names both lanelets of a gap.
  try {
    route_centreline(chain, {node_of(chain, 1), node_of(chain, 3)});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "route: lanelet 1 and lanelet 3 are neither successors nor neighbours");
  }
}

TEST(LaneGraph, BidirectionalLaneletGivesANodePerDirection) {
  MapBuilder b;
  b.lanelet(7, b.line(straight(0, 3, 50, 3)), b.line(straight(0, -3, 50, -3)), false, false, "", false);
  b.lanelet(8, b.line(straight(0, 3, 50, 3)), b.line(straight(0, -10, 50, -10)), false, false, "walkway");
  const LaneGraph graph = build_lane_graph(b.map);
  ASSERT_EQ(graph.nodes.size(), 2u);
  EXPECT_EQ(graph.not_drivable.at("walkway"), 1);
  const auto forward = lane_graph_node(graph, 7), backward = lane_graph_node(graph, 7, true);
  ASSERT_TRUE(forward && backward);
  EXPECT_NEAR(graph.nodes[*backward].length, graph.nodes[*forward].length, 1e-9);
  EXPECT_NEAR(graph.nodes[*backward].centreline.front().x(), 50, 1e-9);
  EXPECT_NEAR(graph.nodes[*backward].left_bound.front().y(), -3, 1e-9);  // the right bound, reversed
  EXPECT_EQ(shortest_route(graph, {10, 0}, {40, 0}), std::vector<LaneGraphNodeId>{*forward});
  EXPECT_EQ(shortest_route(graph, {40, 0}, {10, 0}), std::vector<LaneGraphNodeId>{*backward});
}

// A U-turn at the end of a two-way street (one bidirectional lanelet, 50 m): the "light bulb" loop of
// three arcs of radius R (right 60 deg, left 300 deg, right 60 deg) reaches R (1 + sqrt 3) beyond the
// end and comes back to where it left, heading the other way.
TEST(LaneGraph, UTurnLoopsBeyondTheEndAndComesBackToTheWayBack) {
  MapBuilder b;
  b.lanelet(6, b.line(straight(-10, 3, 0, 3)), b.line(straight(-10, -3, 0, -3)));  // one way in: sets the direction
  b.lanelet(7, b.line(straight(0, 3, 50, 3)), b.line(straight(0, -3, 50, -3)), false, false, "", false);
  const LaneGraph graph = build_lane_graph(b.map);
  auto route = route_from_lanelets(graph, {6, 7, 7}, {2});
  ASSERT_EQ(route.size(), 4u);
  EXPECT_EQ(route[1], *lane_graph_node(graph, 7));
  EXPECT_EQ(route[2], kUTurn);
  EXPECT_EQ(route[3], *lane_graph_node(graph, 7, true));
  route.erase(route.begin());
  const RouteLineOptions o;
  const double R = o.u_turn_radius;
  const Polyline2d line = route_centreline(graph, route, o);
  double reach = 0;
  for (const auto& p : line) reach = std::max(reach, p.x());
  EXPECT_NEAR(reach, 50 + R * (1 + std::sqrt(3.0)), 0.05);
  EXPECT_NEAR(line.back().x(), 0, 1e-9);
  // The loop: arcs of 60 + 300 + 60 deg at radius R.
  const double loop = 7 * std::numbers::pi / 3 * R;
  EXPECT_NEAR(polyline_length(line), 50 + loop + 50, 0.1);
  EXPECT_NEAR(route_length(graph, route), 50 + loop + 50, 0.1);
  // Every point of the loop is R from one of the three centres (x ahead, y left of the way out's end).
  const Eigen::Vector2d c1(50, -R), c2(50 + R * std::sqrt(3.0), 0), c3(50, R);
  for (const auto& p : line) {
    if (p.x() <= 50) continue;
    const double d =
        std::min({std::abs((p - c1).norm() - R), std::abs((p - c2).norm() - R), std::abs((p - c3).norm() - R)});
    EXPECT_LT(d, 1e-6) << p.transpose();
  }
  // Driven, the line keeps to a car's turning radius: the smoothed loop's tightest bend is no tighter.
  const Path driven = make_path(route_driven_line(graph, route), false);
  for (double s = 0; s < driven.length; s += 0.5) EXPECT_LT(std::abs(driven.curvature_at(s)), 1.0 / (R - 0.3));
}

// A divided road's opposite lane, 3.5 m to the left: the loop comes back into it. A way back that
// starts 40 m before the turn or heads the same way is no U-turn, and the message says what would be.
TEST(LaneGraph, UTurnIntoTheOppositeLaneAndErrors) {
  MapBuilder b;
  b.lanelet(1, b.line(straight(0, 0, 50, 0)), b.line(straight(0, -3.5, 50, -3.5)));
  b.lanelet(2, b.line(straight(50, 0, 0, 0)), b.line(straight(50, 3.5, 0, 3.5)));
  b.lanelet(3, b.line(straight(10, 3.5, 0, 3.5)), b.line(straight(10, 7, 0, 7)));    // starts 40 m back
  b.lanelet(4, b.line(straight(50, 7, 60, 7)), b.line(straight(50, 3.5, 60, 3.5)));  // heads on
  const LaneGraph graph = build_lane_graph(b.map);
  const auto route = route_from_lanelets(graph, {1, 2}, {1});
  const Polyline2d line = route_centreline(graph, route);
  EXPECT_NEAR(line.back().x(), 0, 1e-9);
  EXPECT_NEAR(line.back().y(), 1.75, 1e-9);
  const auto u_turn_error = [&](Lanelet2Id back) {
    try {
      route_from_lanelets(graph, {1, back}, {1});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(u_turn_error(3),
            "route: no U-turn takes lanelet 1 back into lanelet 3: the way back must start near "
            "where the way out ends, heading back");
  EXPECT_NE(u_turn_error(4).find("no U-turn takes lanelet 1 back into lanelet 4"), std::string::npos);
  EXPECT_THROW(route_from_lanelets(graph, {1, 2}, {0}), InputError);  // nothing to turn from
}

TEST(LaneGraph, CoveringRoutesCoverEveryLanelet) {
  const LaneGraph graph = build_lane_graph(t_junction().map);
  const auto routes = covering_routes(graph);
  std::set<Lanelet2Id> covered;
  for (const auto& route : routes) {
    for (size_t i = 0; i < route.size(); ++i) {
      covered.insert(graph.nodes[route[i]].lanelet);
      if (i) {
        const auto& s = graph.nodes[route[i - 1]].successors;
        EXPECT_NE(std::find(s.begin(), s.end(), route[i]), s.end()) << "not a chain of successors";
      }
    }
  }
  EXPECT_EQ(covered.size(), 12u);
  for (size_t i = 1; i < routes.size(); ++i)
    EXPECT_GE(route_length(graph, routes[i - 1]), route_length(graph, routes[i]));  // longest first
  // Every drive goes in, through one movement, and out: six movements need six drives, and no drive
  // starts inside the junction.
  EXPECT_EQ(routes.size(), 6u);
  for (const auto& route : routes) EXPECT_LT(graph.nodes[route.front()].lanelet, 40) << "starts in the junction";
}

TEST(LaneGraph, RingIsOneStronglyConnectedComponent) {
  MapBuilder b;
  // A 40 m square loop driven anticlockwise (inner corners on the left, outer on the right), plus a lone
  // lanelet far away.
  const Eigen::Vector2d inner[] = {{0, 0}, {40, 0}, {40, 40}, {0, 40}};
  const Eigen::Vector2d outer[] = {{-3.5, -3.5}, {43.5, -3.5}, {43.5, 43.5}, {-3.5, 43.5}};
  for (int i = 0; i < 4; ++i)
    b.lanelet(i + 1, b.line({inner[i], inner[(i + 1) % 4]}), b.line({outer[i], outer[(i + 1) % 4]}));
  b.lanelet(9, b.line(straight(500, 0, 550, 0)), b.line(straight(500, -3.5, 550, -3.5)));
  const LaneGraph graph = build_lane_graph(b.map);
  const LaneGraphComponents components = lane_graph_components(graph);
  EXPECT_EQ(components.strong_sizes, (std::vector<int>{4, 1})) << describe_components(components);
  EXPECT_EQ(components.weak_sizes, (std::vector<int>{4, 1}));
  EXPECT_EQ(components.strong_of[node_of(graph, 1)], 0);
  EXPECT_EQ(reachable_from(graph, node_of(graph, 3)).size(), 4u);
  EXPECT_EQ(describe_components(components),
            "5 nodes; 2 strongly connected components (sizes 4, 1); 2 weakly connected (sizes 4, 1)");
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

// Steps of the route that take one of several ways out of a lanelet, or come in where several meet:
// junctions passed.
int junctions_on(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route) {
  std::vector<int> predecessors(graph.nodes.size(), 0);
  for (const auto& node : graph.nodes)
    for (LaneGraphNodeId s : node.successors) ++predecessors[s];
  int count = 0;
  for (size_t i = 1; i < route.size(); ++i) {
    if (route[i - 1] == kUTurn || route[i] == kUTurn) continue;
    if (graph.nodes[route[i - 1]].successors.size() > 1 || predecessors[route[i]] > 1) ++count;
  }
  return count;
}

// The real Karlsruhe map (Lanelet2's mapping example, issue 35) when ../shared/data holds it: its
// components, and the drive scenarios/karlsruhe.yaml gives, lanelet by lanelet. The map is a mapping
// example, not a closed network: its largest part (a big roundabout) is edged by road borders, with
// hardly a curbstone; the part drawn with curbs is a tree of two-way streets around a small roundabout
// whose ends leave the map. So the drive turns back where a street leaves the map: at least 1.5 km,
// through junctions, most of it with a curbstone within reach of the HDL-32E's curb detection.
TEST(LaneGraph, KarlsruheScenarioDrivesOneAndAHalfKilometresAlongCurbs) {
  const std::string data = std::string(LIDARLOOP_DATA_DIR);
  const std::string path = data + "/../shared/data/maps/lanelet2/karlsruhe_mapping_example.osm";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not there";
  const Lanelet2Map map = read_lanelet2(path);
  const LaneGraph graph = build_lane_graph(map);
  const LaneGraphComponents components = lane_graph_components(graph);
  std::cout << "Karlsruhe: " << graph.nodes_of.size() << " drivable lanelets; " << describe_components(components)
            << "\n";
  // 337 road + 8 highway lanelets, less the 17 roads tagged for bicycles and pedestrians only.
  EXPECT_EQ(graph.nodes_of.size(), 328u);

  const Scenario scenario = load_scenario(data + "/scenarios/karlsruhe.yaml");
  const PathSpec& spec = scenario.ego.route;
  const auto route = route_from_lanelets(graph, spec.lanelets, spec.u_turns);
  const double length = route_length(graph, route);
  const Polyline2d line = route_driven_line(graph, route);
  // Curbstones within 10 m of the driven line (the detector looks 25 m out; a street's curbs are 3-6 m
  // from its middle), sampled every metre.
  std::vector<const Lanelet2LineString*> curbstones;
  for (const auto& [id, l] : map.lines)
    if (l.type == "curbstone") curbstones.push_back(&l);
  int near = 0, samples = 0;
  for (double s = 0; s < polyline_length(line); s += 1, ++samples) {
    const Eigen::Vector2d p = sample_polyline(line, s).point;
    const bool curb = std::any_of(curbstones.begin(), curbstones.end(), [&](const Lanelet2LineString* c) {
      for (size_t i = 1; i < c->points.size(); ++i) {
        const Eigen::Vector2d a = c->points[i - 1].head<2>(), b = c->points[i].head<2>();
        const double t = std::clamp((p - a).dot(b - a) / std::max((b - a).squaredNorm(), 1e-12), 0.0, 1.0);
        if ((a + t * (b - a) - p).norm() < 10) return true;
      }
      return false;
    });
    near += curb;
  }
  const long u_turns = std::count(route.begin(), route.end(), kUTurn);
  std::cout << "  drive " << polyline_length(line) << " m (" << length << " m by lanelets), "
            << junctions_on(graph, route) << " junctions, " << u_turns << " U-turns; a curbstone within 10 m along "
            << 100.0 * near / samples << " % of it\n";
  EXPECT_GE(length, 1500);
  EXPECT_GE(polyline_length(line), 1500);
  EXPECT_GE(junctions_on(graph, route), 10);
  EXPECT_GE(double(near) / samples, 0.8);
}

}  // namespace
}  // namespace lidarloop
