#include "sim/lane_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <queue>
#include <set>
#include <sstream>
#include <unordered_map>

#include "common/input_error.hpp"
#include "common/pose2d.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A node's bounds while the graph is built: 3-D points in the driving direction, their node ids where
// the map gives them (0 where not), the line strings they come from and whether the node runs against
// the line's own point order (which decides what solid_dashed allows, LinestringTagging.md).
struct Bounds {
  std::vector<Eigen::Vector3d> left, right;
  std::vector<Lanelet2Id> left_ids, right_ids;
  const Lanelet2LineString* left_line = nullptr;
  const Lanelet2LineString* right_line = nullptr;
  bool left_inverted = false, right_inverted = false;
};

const Lanelet2LineString* find_line(const Lanelet2Map& map, Lanelet2Id id) {
  const auto it = map.lines.find(id);
  return it == map.lines.end() ? nullptr : &it->second;
}

// The bound's point ids in the lanelet's direction, or zeros when the line is unknown or its points are
// not the ones the lanelet holds (then only distances decide equality).
std::vector<Lanelet2Id> oriented_ids(const Lanelet2LineString* line, bool inverted, size_t size) {
  if (!line || line->point_ids.size() != size) return std::vector<Lanelet2Id>(size, 0);
  std::vector<Lanelet2Id> ids = line->point_ids;
  if (inverted) std::reverse(ids.begin(), ids.end());
  return ids;
}

Bounds forward_bounds(const Lanelet2Map& map, const Lanelet2Lanelet& lanelet) {
  Bounds b;
  b.left = lanelet.left_points;
  b.right = lanelet.right_points;
  b.left_line = find_line(map, lanelet.left);
  b.right_line = find_line(map, lanelet.right);
  b.left_inverted = lanelet.left_inverted;
  b.right_inverted = lanelet.right_inverted;
  b.left_ids = oriented_ids(b.left_line, b.left_inverted, b.left.size());
  b.right_ids = oriented_ids(b.right_line, b.right_inverted, b.right.size());
  return b;
}

// Driven the other way, the right bound reversed is on the driver's left (Lanelet2's Lanelet::invert).
Bounds reversed_bounds(const Bounds& forward) {
  Bounds b;
  b.left.assign(forward.right.rbegin(), forward.right.rend());
  b.right.assign(forward.left.rbegin(), forward.left.rend());
  b.left_ids.assign(forward.right_ids.rbegin(), forward.right_ids.rend());
  b.right_ids.assign(forward.left_ids.rbegin(), forward.left_ids.rend());
  b.left_line = forward.right_line;
  b.right_line = forward.left_line;
  b.left_inverted = !forward.right_inverted;
  b.right_inverted = !forward.left_inverted;
  return b;
}

Polyline2d planar(const std::vector<Eigen::Vector3d>& points) {
  Polyline2d out;
  out.reserve(points.size());
  for (const auto& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

// The midpoints of both bounds sampled at equal fractions of their arc lengths: Lanelet2's own
// centreline (Lanelet::centerline) pairs points more cleverly, but on a lanelet whose bounds have
// different numbers of points, equal fractions are what keeps the line in the middle.
Polyline2d centreline_from_bounds(const Polyline2d& left, const Polyline2d& right, double step) {
  const double left_length = polyline_length(left), right_length = polyline_length(right);
  const size_t by_length = static_cast<size_t>(std::ceil(std::max(left_length, right_length) / step)) + 1;
  const size_t n = std::max({left.size(), right.size(), by_length, size_t{2}});
  Polyline2d out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(n - 1);
    out.push_back(0.5 *
                  (sample_polyline(left, t * left_length).point + sample_polyline(right, t * right_length).point));
  }
  return out;
}

// Lanelet2's points are equal when they are the same point (geometry::follows compares points); maps
// that do not share nodes where lanes meet still connect within the tolerance.
bool same_point(Lanelet2Id id_a, const Eigen::Vector3d& a, Lanelet2Id id_b, const Eigen::Vector3d& b,
                double tolerance) {
  if (id_a != 0 && id_a == id_b) return true;
  return (a - b).norm() <= tolerance;
}

bool same_bound(const std::vector<Eigen::Vector3d>& a, const std::vector<Lanelet2Id>& a_ids,
                const std::vector<Eigen::Vector3d>& b, const std::vector<Lanelet2Id>& b_ids, double tolerance) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!same_point(a_ids[i], a[i], b_ids[i], b[i], tolerance)) return false;
  return true;
}

// Buckets of points on a planar grid, so that finding the lanelets that start where another ends is not
// quadratic in the map's size (Autoware maps of a city hold tens of thousands of lanelets).
struct PointGrid {
  double cell = 1.0;
  std::unordered_map<uint64_t, std::vector<int>> buckets;

  static uint64_t key(int64_t ix, int64_t iy) {
    return (static_cast<uint64_t>(ix) << 32) ^ (static_cast<uint64_t>(iy) & 0xffffffffu);
  }
  void add(const Eigen::Vector3d& p, int value) {
    buckets[key(std::llround(std::floor(p.x() / cell)), std::llround(std::floor(p.y() / cell)))].push_back(value);
  }
  // Values in the 3 x 3 cells around p (the tolerance is far below a cell).
  std::vector<int> near(const Eigen::Vector3d& p) const {
    std::vector<int> out;
    const int64_t ix = std::llround(std::floor(p.x() / cell)), iy = std::llround(std::floor(p.y() / cell));
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = buckets.find(key(ix + dx, iy + dy));
        if (it != buckets.end()) out.insert(out.end(), it->second.begin(), it->second.end());
      }
    return out;
  }
};

bool truthy(const std::string& value) { return value == "yes" || value == "true" || value == "1"; }

// An edge a car may take: to a successor (cost: its length) or a lane change (cost: the penalty).
struct Edge {
  LaneGraphNodeId to;
  bool lane_change;
};
std::vector<Edge> drivable_edges(const LaneGraphNode& node) {
  std::vector<Edge> out;
  for (LaneGraphNodeId s : node.successors) out.push_back({s, false});
  if (node.left && node.can_change_left) out.push_back({*node.left, true});
  if (node.right && node.can_change_right) out.push_back({*node.right, true});
  return out;
}

bool is_neighbour(const LaneGraphNode& a, LaneGraphNodeId b) { return a.left == b || a.right == b; }
bool is_successor(const LaneGraphNode& a, LaneGraphNodeId b) {
  return std::find(a.successors.begin(), a.successors.end(), b) != a.successors.end();
}
bool may_change_into(const LaneGraphNode& a, LaneGraphNodeId b) {
  return (a.left == b && a.can_change_left) || (a.right == b && a.can_change_right);
}

bool inside_polygon(const Polyline2d& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d &a = polygon[i], &b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

double segment_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = b - a;
  const double len2 = d.squaredNorm();
  const double u = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (a + u * d - p).norm();
}

// Planar distance from p to the lanelet's area (0 inside): the polygon of its left bound and its right
// bound reversed, as Lanelet2's Lanelet::polygon2d.
double distance_to_node(const LaneGraphNode& node, const Eigen::Vector2d& p) {
  Polyline2d polygon = node.left_bound;
  polygon.insert(polygon.end(), node.right_bound.rbegin(), node.right_bound.rend());
  if (polygon.size() >= 3 && inside_polygon(polygon, p)) return 0;
  double best = kInf;
  for (size_t i = 0; i < polygon.size(); ++i)
    best = std::min(best, segment_distance(polygon[i], polygon[(i + 1) % polygon.size()], p));
  return best;
}

struct Snap {
  LaneGraphNodeId node;
  double s;  // arc length of the point's projection on the centreline
};

std::string point_text(const Eigen::Vector2d& p) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "(%.1f, %.1f)", p.x(), p.y());
  return buffer;
}

// The nodes whose area holds p (both directions of a bidirectional lanelet, overlapping lanelets in a
// junction), else the nearest ones.
std::vector<Snap> snap_point(const LaneGraph& graph, const Eigen::Vector2d& p, double max_snap_m, const char* what) {
  if (graph.nodes.empty()) throw InputError("route: the map has no drivable lanelets");
  std::vector<double> distance(graph.nodes.size());
  double nearest = kInf;
  LaneGraphNodeId nearest_node = 0;
  for (size_t i = 0; i < graph.nodes.size(); ++i) {
    distance[i] = distance_to_node(graph.nodes[i], p);
    if (distance[i] < nearest) nearest = distance[i], nearest_node = static_cast<LaneGraphNodeId>(i);
  }
  if (nearest > max_snap_m) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, " is %.1f m from the nearest drivable lanelet (%lld), more than %.1f m",
                  nearest, static_cast<long long>(graph.nodes[nearest_node].lanelet), max_snap_m);
    throw InputError(std::string("route: ") + what + " " + point_text(p) + buffer);
  }
  std::vector<Snap> out;
  for (size_t i = 0; i < graph.nodes.size(); ++i)
    if (distance[i] <= nearest + 0.01)
      out.push_back({static_cast<LaneGraphNodeId>(i), project_onto_polyline(graph.nodes[i].centreline, p)});
  return out;
}

// Where a run of lane changes is: each run is driven as one stretch (route_centreline).
std::vector<std::vector<LaneGraphNodeId>> split_runs(const LaneGraph& graph,
                                                     const std::vector<LaneGraphNodeId>& route) {
  std::vector<std::vector<LaneGraphNodeId>> runs;
  for (size_t i = 0; i < route.size(); ++i) {
    if (route[i] == kUTurn) {
      if (i == 0 || i + 1 == route.size() || route[i - 1] == kUTurn)
        throw InputError("route: a U-turn must come between two lanelets");
      runs.push_back({kUTurn});
      continue;
    }
    if (route[i] < 0 || static_cast<size_t>(route[i]) >= graph.nodes.size())
      throw InputError("route: node " + std::to_string(route[i]) + " is not in the lane graph");
    if (i == 0 || route[i - 1] == kUTurn) {
      runs.push_back({route[i]});
      continue;
    }
    const LaneGraphNode& previous = graph.nodes[route[i - 1]];
    if (is_neighbour(previous, route[i])) {
      runs.back().push_back(route[i]);
    } else if (is_successor(previous, route[i])) {
      runs.push_back({route[i]});
    } else {
      throw InputError("route: " + describe_node(graph, route[i - 1]) + " and " + describe_node(graph, route[i]) +
                       " are neither successors nor neighbours");
    }
  }
  return runs;
}

double mean_length(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& run) {
  double sum = 0;
  for (LaneGraphNodeId n : run) sum += graph.nodes[n].length;
  return sum / static_cast<double>(run.size());
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// A run of k parallel lanelets driven one after the other, each for a k-th of the way (by fraction of
// its own length, so that inner and outer lanes of a bend line up), with a smoothstep blend between
// neighbours over lane_change_length around each change.
Polyline2d run_centreline(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& run, double lane_change_length) {
  if (run.size() == 1) return graph.nodes[run.front()].centreline;
  const double length = std::max(mean_length(graph, run), 1e-6);
  const double k = static_cast<double>(run.size());
  const double half = std::min(0.5 * lane_change_length / length, 0.5 / k);  // in fractions of the run
  const size_t samples = static_cast<size_t>(std::ceil(length / 0.5)) + 1;
  Polyline2d out;
  out.reserve(samples);
  for (size_t i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(samples - 1);
    double lane = 0;  // continuous index into the run
    for (size_t j = 1; j < run.size(); ++j) {
      const double boundary = static_cast<double>(j) / k;
      lane += half > 0 ? smoothstep((t - boundary + half) / (2 * half)) : (t >= boundary ? 1.0 : 0.0);
    }
    const size_t a = std::min(static_cast<size_t>(lane), run.size() - 2);
    const double w = lane - static_cast<double>(a);
    const LaneGraphNode &na = graph.nodes[run[a]], &nb = graph.nodes[run[a + 1]];
    out.push_back((1 - w) * sample_polyline(na.centreline, t * na.length).point +
                  w * sample_polyline(nb.centreline, t * nb.length).point);
  }
  return out;
}

// Where a node ends and the next starts: position and heading of its centreline's first / last segment.
Pose2d centreline_end(const LaneGraphNode& n, bool last) {
  const Polyline2d& c = n.centreline;
  const Eigen::Vector2d a = last ? c[c.size() - 2] : c[0], b = last ? c.back() : c[1];
  const Eigen::Vector2d at = last ? b : a;
  return {at.x(), at.y(), std::atan2(b.y() - a.y(), b.x() - a.x())};
}

// The loop of a U-turn from the end of `out` to the start of `back`, without its two ends; nullopt when
// `back` does not start where such a loop reaches (RouteLineOptions). In the frame of out's end (x
// ahead, y left), back starts at (qx, qy) heading about -x. Three arcs of radius R: right around C1 =
// (x0, -R), left around C2, right around C3 = (x0, qy + R), with C2 ahead where the circles about C1 and
// C3 of radius 2 R cross (the arcs are tangent there); x0 = max(qx, 0), a straight before or after.
std::optional<Polyline2d> u_turn_loop(const LaneGraphNode& out, const LaneGraphNode& back, const RouteLineOptions& o) {
  const Pose2d p = centreline_end(out, true), q = centreline_end(back, false);
  const Eigen::Rotation2Dd to_world(p.yaw);
  const Eigen::Vector2d origin(p.x, p.y);
  const Eigen::Vector2d local = to_world.inverse() * (Eigen::Vector2d(q.x, q.y) - origin);
  const double R = o.u_turn_radius, qx = local.x(), qy = local.y();
  constexpr double kSideSlack = 0.5;  // m: a way back drawn a little to the right of the way out still turns
  if (std::abs(qx) > o.max_u_turn_shift || qy < -kSideSlack || qy > 2 * R ||
      std::abs(wrap_angle(q.yaw - p.yaw - std::numbers::pi)) > o.max_u_turn_angle)
    return std::nullopt;
  const double x0 = std::max(qx, 0.0), y1 = std::max(qy, 0.0);
  const Eigen::Vector2d c1(x0, -R), c3(x0, y1 + R);
  const double half = (y1 + 2 * R) / 2;
  const Eigen::Vector2d c2(x0 + std::sqrt(4 * R * R - half * half), y1 / 2);
  const auto angle = [](const Eigen::Vector2d& v) { return std::atan2(v.y(), v.x()); };
  constexpr double kTwoPi = 2 * std::numbers::pi;
  const auto positive = [&](double a) { return a - kTwoPi * std::floor(a / kTwoPi); };
  Polyline2d local_line;
  const auto arc = [&](const Eigen::Vector2d& centre, double from, double sweep) {  // sweep > 0: left
    const int n = std::max(2, static_cast<int>(std::ceil(std::abs(sweep) * R / o.step)));
    for (int i = 0; i <= n; ++i) {
      const double a = from + sweep * i / n;
      local_line.push_back(centre + R * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
  };
  if (qx > 0) local_line.push_back({0, 0});
  const double a1 = angle(c2 - c1), a2_from = angle(c1 - c2), a2_to = angle(c3 - c2), a3 = angle(c2 - c3);
  arc(c1, std::numbers::pi / 2, -positive(std::numbers::pi / 2 - a1));
  arc(c2, a2_from, positive(a2_to - a2_from));
  arc(c3, a3, -positive(a3 + std::numbers::pi / 2));
  Polyline2d world;
  for (const Eigen::Vector2d& v : local_line) world.push_back(origin + to_world * v);
  if (qx < 0) world.push_back(origin + to_world * Eigen::Vector2d(qx, y1));
  return world;
}

Polyline2d u_turn_or_throw(const LaneGraph& graph, LaneGraphNodeId out, LaneGraphNodeId back,
                           const RouteLineOptions& o) {
  std::optional<Polyline2d> loop = u_turn_loop(graph.nodes[out], graph.nodes[back], o);
  if (!loop)
    throw InputError("route: a U-turn cannot take " + describe_node(graph, out) + " back into " +
                     describe_node(graph, back) + ": the way back must start within " +
                     std::to_string(int(o.max_u_turn_shift)) + " m of where the way out ends, on its left, " +
                     "heading back");
  return *loop;
}

}  // namespace

bool drivable_subtype(const std::string& subtype) {
  return subtype.empty() || subtype == "road" || subtype == "highway" || subtype == "play_street" || subtype == "exit";
}

bool vehicles_allowed(const Lanelet2Tags& tags) {
  // GenericTrafficRules::canPass: any `participant:` tag overrides the subtype, and then only
  // `participant:vehicle` lets a car in (a road shared by bicycles and pedestrians only, say).
  const bool any =
      std::any_of(tags.begin(), tags.end(), [](const auto& t) { return t.first.starts_with("participant:"); });
  if (!any) return true;
  const auto it = tags.find("participant:vehicle");
  return it != tags.end() && truthy(it->second);
}

bool lane_change_allowed(const Lanelet2LineString& bound, bool to_left) {
  // GenericTrafficRules' getHardcodedChangeType: explicit tags win over the line's type.
  const auto tag = [&](const char* name) -> const std::string* {
    const auto it = bound.tags.find(name);
    return it == bound.tags.end() ? nullptr : &it->second;
  };
  if (const std::string* v = tag("lane_change")) return truthy(*v);
  const std::string* left = tag("lane_change:left");
  const std::string* right = tag("lane_change:right");
  if (left || right) return to_left ? (left && truthy(*left)) : (right && truthy(*right));
  if (bound.type == "virtual") return true;
  if (bound.type != "line_thin" && bound.type != "line_thick") return false;
  if (bound.subtype == "dashed") return true;
  if (bound.subtype == "solid_dashed") return to_left;
  if (bound.subtype == "dashed_solid") return !to_left;
  return false;
}

LaneGraph build_lane_graph(const Lanelet2Map& map, const LaneGraphOptions& options) {
  LaneGraph graph;
  std::vector<Bounds> bounds;
  for (const Lanelet2Lanelet& lanelet : map.lanelets) {
    if (!drivable_subtype(lanelet.subtype)) {
      ++graph.not_drivable[lanelet.subtype];
      continue;
    }
    if (!vehicles_allowed(lanelet.tags)) {
      ++graph.not_drivable["participant"];
      continue;
    }
    if (lanelet.left_points.size() < 2 || lanelet.right_points.size() < 2) {
      ++graph.not_drivable["broken"];
      continue;
    }
    const Bounds forward = forward_bounds(map, lanelet);
    // An explicit centreline (Lanelet2's `centerline` member) is taken as drawn, turned to run the
    // lanelet's way.
    Polyline2d explicit_centre;
    if (lanelet.centerline)
      if (const Lanelet2LineString* line = find_line(map, *lanelet.centerline); line && line->points.size() >= 2) {
        explicit_centre = planar(line->points);
        const Eigen::Vector2d start = 0.5 * (planar(forward.left).front() + planar(forward.right).front());
        if ((explicit_centre.back() - start).norm() < (explicit_centre.front() - start).norm())
          std::reverse(explicit_centre.begin(), explicit_centre.end());
      }
    for (bool reversed : {false, true}) {
      // Lanelet2's default is one way (GenericTrafficRules' isDrivingDir): the inverted lanelet is
      // driven only when `one_way` says no.
      if (reversed && lanelet.one_way) break;
      Bounds b = reversed ? reversed_bounds(forward) : forward;
      LaneGraphNode node;
      node.lanelet = lanelet.id;
      node.reversed = reversed;
      node.subtype = lanelet.subtype;
      node.left_bound = planar(b.left);
      node.right_bound = planar(b.right);
      if (!explicit_centre.empty()) {
        node.centreline = explicit_centre;
        if (reversed) std::reverse(node.centreline.begin(), node.centreline.end());
      } else {
        node.centreline = centreline_from_bounds(node.left_bound, node.right_bound, options.centreline_step_m);
      }
      node.length = polyline_length(node.centreline);
      node.speed_limit_mps = lanelet.speed_limit_mps;
      graph.nodes_of[lanelet.id].push_back(static_cast<LaneGraphNodeId>(graph.nodes.size()));
      graph.nodes.push_back(std::move(node));
      bounds.push_back(std::move(b));
    }
  }

  const double tol = options.point_tolerance_m;
  PointGrid starts, right_starts;
  for (size_t i = 0; i < bounds.size(); ++i) {
    starts.add(bounds[i].left.front(), static_cast<int>(i));
    right_starts.add(bounds[i].right.front(), static_cast<int>(i));
  }
  for (size_t i = 0; i < bounds.size(); ++i) {
    const Bounds& a = bounds[i];
    LaneGraphNode& node = graph.nodes[i];
    // Successors: Lanelet2's geometry::follows, the end of one is the start of the other.
    for (int j : starts.near(a.left.back())) {
      const Bounds& b = bounds[j];
      if (static_cast<size_t>(j) == i) continue;
      if (same_point(a.left_ids.back(), a.left.back(), b.left_ids.front(), b.left.front(), tol) &&
          same_point(a.right_ids.back(), a.right.back(), b.right_ids.front(), b.right.front(), tol))
        node.successors.push_back(j);
    }
    std::sort(node.successors.begin(), node.successors.end());
    // Left neighbour: its right bound is this one's left bound, same direction (geometry::leftOf). A
    // bound shared by lanes of opposite directions is no lane change (it runs the other way).
    for (int j : right_starts.near(a.left.front())) {
      const Bounds& b = bounds[j];
      if (static_cast<size_t>(j) == i || !same_bound(a.left, a.left_ids, b.right, b.right_ids, tol)) continue;
      node.left = j;
      graph.nodes[j].right = static_cast<LaneGraphNodeId>(i);
      // Crossing to the driver's left crosses the line to its own left unless the node runs against it.
      node.can_change_left = a.left_line && lane_change_allowed(*a.left_line, !a.left_inverted);
      graph.nodes[j].can_change_right = b.right_line && lane_change_allowed(*b.right_line, b.right_inverted);
    }
  }
  return graph;
}

std::optional<LaneGraphNodeId> lane_graph_node(const LaneGraph& graph, Lanelet2Id lanelet, bool reversed) {
  const auto it = graph.nodes_of.find(lanelet);
  if (it == graph.nodes_of.end()) return std::nullopt;
  for (LaneGraphNodeId n : it->second)
    if (graph.nodes[n].reversed == reversed) return n;
  return std::nullopt;
}

std::string describe_node(const LaneGraph& graph, LaneGraphNodeId node) {
  if (node < 0 || static_cast<size_t>(node) >= graph.nodes.size()) return "node " + std::to_string(node);
  const LaneGraphNode& n = graph.nodes[node];
  return "lanelet " + std::to_string(n.lanelet) + (n.reversed ? " (reversed)" : "");
}

std::vector<LaneGraphNodeId> shortest_route(const LaneGraph& graph, const Eigen::Vector2d& from,
                                            const Eigen::Vector2d& to, const RouteOptions& options) {
  const std::vector<Snap> sources = snap_point(graph, from, options.max_snap_m, "from");
  const std::vector<Snap> targets = snap_point(graph, to, options.max_snap_m, "to");

  // Costs are metres driven to a node's end: the rest of the first node, every successor's length, a
  // lane change's penalty (its lanes run side by side, so the end is about as far); the last node's
  // part beyond `to` is taken off at the end. `origin` marks a node reached straight from a source, so
  // that a source reached again (a loop back to behind `from`) keeps its own predecessor.
  const size_t n = graph.nodes.size();
  std::vector<double> dist(n, kInf);
  std::vector<LaneGraphNodeId> prev(n, -1), origin(n, -1);
  using Item = std::pair<double, LaneGraphNodeId>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  const auto relax = [&](LaneGraphNodeId x, LaneGraphNodeId y, bool lane_change, double base, bool from_source) {
    const double cost = base + (lane_change ? options.lane_change_cost_m : graph.nodes[y].length);
    if (cost >= dist[y]) return;
    dist[y] = cost;
    prev[y] = from_source ? -1 : x;
    origin[y] = from_source ? x : -1;
    queue.push({cost, y});
  };
  for (const Snap& s : sources)
    for (const Edge& e : drivable_edges(graph.nodes[s.node]))
      relax(s.node, e.to, e.lane_change, graph.nodes[s.node].length - s.s, true);
  while (!queue.empty()) {
    const auto [d, x] = queue.top();
    queue.pop();
    if (d > dist[x]) continue;
    for (const Edge& e : drivable_edges(graph.nodes[x])) relax(x, e.to, e.lane_change, d, false);
  }

  double best = kInf;
  std::vector<LaneGraphNodeId> route;
  for (const Snap& t : targets) {
    for (const Snap& s : sources)  // both in one lanelet, `to` ahead: no edge needed
      if (s.node == t.node && t.s >= s.s && t.s - s.s < best) best = t.s - s.s, route = {s.node};
    const double total = dist[t.node] - (graph.nodes[t.node].length - t.s);
    if (dist[t.node] == kInf || total >= best) continue;
    best = total;
    route = {t.node};
    LaneGraphNodeId x = t.node;
    while (origin[x] < 0) route.push_back(x = prev[x]);
    route.push_back(origin[x]);
    std::reverse(route.begin(), route.end());
  }
  if (route.empty())
    throw InputError("route: no drivable route from " + point_text(from) + " (" +
                     describe_node(graph, sources.front().node) + ") to " + point_text(to) + " (" +
                     describe_node(graph, targets.front().node) +
                     "): the lanelets are not connected by successors and allowed lane changes");
  return route;
}

std::vector<LaneGraphNodeId> route_from_lanelets(const LaneGraph& graph, const std::vector<Lanelet2Id>& lanelets,
                                                 const std::vector<size_t>& u_turns) {
  const std::set<size_t> turn_before(u_turns.begin(), u_turns.end());
  if (!turn_before.empty() && (*turn_before.begin() == 0 || *turn_before.rbegin() >= lanelets.size()))
    throw InputError("route: a U-turn must come between two lanelets");
  if (lanelets.empty()) throw InputError("route: the list of lanelets is empty");
  // Each lanelet may have two nodes (a bidirectional one): keep, for each candidate, the one before it
  // that connects (a tiny Viterbi), so the direction is chosen by what comes before and after.
  std::vector<std::vector<LaneGraphNodeId>> candidates;
  for (Lanelet2Id id : lanelets) {
    const auto it = graph.nodes_of.find(id);
    if (it == graph.nodes_of.end())
      throw InputError("route: lanelet " + std::to_string(id) + " is not a drivable lanelet of the map");
    candidates.push_back(it->second);
  }
  std::vector<std::map<LaneGraphNodeId, LaneGraphNodeId>> back(lanelets.size());
  for (LaneGraphNodeId c : candidates[0]) back[0][c] = -1;
  for (size_t i = 1; i < lanelets.size(); ++i) {
    bool beside = false;
    for (const auto& entry : back[i - 1])
      for (LaneGraphNodeId c : candidates[i]) {
        const LaneGraphNodeId p = entry.first;
        const bool connects = turn_before.count(i)
                                  ? u_turn_loop(graph.nodes[p], graph.nodes[c], {}).has_value()
                                  : is_successor(graph.nodes[p], c) || may_change_into(graph.nodes[p], c);
        if (connects) back[i].emplace(c, p);
        beside = beside || is_neighbour(graph.nodes[p], c);
      }
    if (back[i].empty()) {
      const std::string a = std::to_string(lanelets[i - 1]), b = std::to_string(lanelets[i]);
      if (turn_before.count(i))
        throw InputError("route: no U-turn takes lanelet " + a + " back into lanelet " + b +
                         ": the way back must start near where the way out ends, heading back");
      throw InputError("route: lanelet " + b +
                       (beside ? " is beside lanelet " + a +
                                     " but their shared bound forbids "
                                     "a lane change"
                               : " neither follows lanelet " + a + " nor is beside it"));
    }
  }
  std::vector<LaneGraphNodeId> nodes(lanelets.size());
  nodes.back() = back.back().begin()->first;
  for (size_t i = lanelets.size() - 1; i > 0; --i) nodes[i - 1] = back[i].at(nodes[i]);
  std::vector<LaneGraphNodeId> route;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (turn_before.count(i)) route.push_back(kUTurn);
    route.push_back(nodes[i]);
  }
  return route;
}

Polyline2d route_centreline(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                            const RouteLineOptions& options) {
  const std::vector<std::vector<LaneGraphNodeId>> runs = split_runs(graph, route);
  Polyline2d out;
  for (size_t r = 0; r < runs.size(); ++r) {
    const Polyline2d piece = runs[r].front() == kUTurn
                                 ? u_turn_or_throw(graph, runs[r - 1].back(), runs[r + 1].front(), options)
                                 : run_centreline(graph, runs[r], options.lane_change_length);
    for (const Eigen::Vector2d& p : piece)
      if (out.empty() || (p - out.back()).norm() > 1e-3) out.push_back(p);
  }
  return out;
}

Polyline2d route_driven_line(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                             const RouteLineOptions& options) {
  return smooth_polyline(route_centreline(graph, route, options), options.smoothing_sigma, options.step);
}

double route_length(const LaneGraph& graph, const std::vector<LaneGraphNodeId>& route,
                    const RouteLineOptions& options) {
  const std::vector<std::vector<LaneGraphNodeId>> runs = split_runs(graph, route);
  double length = 0;
  for (size_t r = 0; r < runs.size(); ++r)
    length += runs[r].front() == kUTurn
                  ? polyline_length(u_turn_or_throw(graph, runs[r - 1].back(), runs[r + 1].front(), options))
                  : mean_length(graph, runs[r]);
  return length;
}

namespace {

// Dijkstra from `start` over `next` (successors, or predecessors to search backwards); the cost of a
// node is the metres driven on the lanelets strictly between `start` and it, searched up to max_cost.
// Stops at the first node other than `start` for which `stop` holds; `order` lists the nodes as settled.
struct Search {
  std::map<LaneGraphNodeId, double> dist;
  std::map<LaneGraphNodeId, LaneGraphNodeId> parent;
  std::vector<LaneGraphNodeId> order;
  LaneGraphNodeId stopped_at = -1;
};
Search bounded_search(const LaneGraph& graph, LaneGraphNodeId start,
                      const std::vector<std::vector<LaneGraphNodeId>>& next, double max_cost,
                      const std::function<bool(LaneGraphNodeId)>& stop) {
  Search s;
  s.dist[start] = 0;
  using Item = std::pair<double, LaneGraphNodeId>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  queue.push({0.0, start});
  while (!queue.empty()) {
    const auto [d, x] = queue.top();
    queue.pop();
    if (d > s.dist.at(x)) continue;
    s.order.push_back(x);
    if (x != start && stop(x)) {
      s.stopped_at = x;
      break;
    }
    const double through = x == start ? 0.0 : d + graph.nodes[x].length;
    if (through > max_cost) continue;
    for (LaneGraphNodeId y : next[x]) {
      const auto it = s.dist.find(y);
      if (it != s.dist.end() && it->second <= through) continue;
      s.dist[y] = through;
      s.parent[y] = x;
      queue.push({through, y});
    }
  }
  return s;
}

}  // namespace

std::vector<std::vector<LaneGraphNodeId>> covering_routes(const LaneGraph& graph, double max_detour_m) {
  const size_t n = graph.nodes.size();
  std::vector<std::vector<LaneGraphNodeId>> successors(n), predecessors(n);
  for (size_t i = 0; i < n; ++i) {
    successors[i] = graph.nodes[i].successors;
    for (LaneGraphNodeId s : graph.nodes[i].successors) predecessors[s].push_back(static_cast<LaneGraphNodeId>(i));
  }
  std::set<Lanelet2Id> covered;
  const auto uncovered = [&](LaneGraphNodeId x) { return !covered.count(graph.nodes[x].lanelet); };
  const auto cover = [&](const std::vector<LaneGraphNodeId>& nodes) {
    for (LaneGraphNodeId x : nodes) covered.insert(graph.nodes[x].lanelet);
  };

  std::vector<std::vector<LaneGraphNodeId>> routes;
  for (;;) {
    // The first uncovered lanelet, one where the network starts (nothing leads in) if there is one.
    LaneGraphNodeId first = -1;
    for (size_t i = 0; i < n && first < 0; ++i)
      if (uncovered(static_cast<LaneGraphNodeId>(i)) && predecessors[i].empty())
        first = static_cast<LaneGraphNodeId>(i);
    for (size_t i = 0; i < n && first < 0; ++i)
      if (uncovered(static_cast<LaneGraphNodeId>(i))) first = static_cast<LaneGraphNodeId>(i);
    if (first < 0) break;
    // Lead in from behind (within the detour): from the nearest lanelet where the network starts, else
    // from as far back as allowed, so that a drive does not begin inside a junction.
    const Search back = bounded_search(graph, first, predecessors, max_detour_m, [](LaneGraphNodeId) { return false; });
    LaneGraphNodeId start = first;
    for (LaneGraphNodeId x : back.order) {
      const bool source = predecessors[x].empty(), best_is_source = predecessors[start].empty();
      if (source ? !best_is_source || back.dist.at(x) < back.dist.at(start)
                 : !best_is_source && back.dist.at(x) > back.dist.at(start))
        start = x;
    }
    std::vector<LaneGraphNodeId> route;
    for (LaneGraphNodeId x = start; x != first; x = back.parent.at(x)) route.push_back(x);
    route.push_back(first);
    cover(route);
    // Then on, each time to the nearest uncovered lanelet ahead.
    for (;;) {
      const Search ahead = bounded_search(graph, route.back(), successors, max_detour_m, uncovered);
      if (ahead.stopped_at < 0) break;
      std::vector<LaneGraphNodeId> step;
      for (LaneGraphNodeId x = ahead.stopped_at; x != route.back(); x = ahead.parent.at(x)) step.push_back(x);
      route.insert(route.end(), step.rbegin(), step.rend());
      cover(step);
    }
    routes.push_back(std::move(route));
  }
  std::stable_sort(routes.begin(), routes.end(),
                   [&](const auto& a, const auto& b) { return route_length(graph, a) > route_length(graph, b); });
  return routes;
}

namespace {

// Component labels renumbered so that 0 is the largest; sizes largest first.
void rank_components(std::vector<int>& label, std::vector<int>& sizes) {
  int count = label.empty() ? 0 : *std::max_element(label.begin(), label.end()) + 1;
  std::vector<int> raw(count, 0);
  for (int l : label) ++raw[l];
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return raw[a] > raw[b]; });
  std::vector<int> rank(count);
  sizes.assign(count, 0);
  for (int r = 0; r < count; ++r) rank[order[r]] = r, sizes[r] = raw[order[r]];
  for (int& l : label) l = rank[l];
}

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

LaneGraphComponents lane_graph_components(const LaneGraph& graph) {
  const int n = static_cast<int>(graph.nodes.size());
  std::vector<std::vector<int>> out(n), in(n);
  for (int i = 0; i < n; ++i)
    for (const Edge& e : drivable_edges(graph.nodes[i])) out[i].push_back(e.to), in[e.to].push_back(i);

  // Kosaraju, both passes iterative (a long chain of lanelets would overflow a recursive one).
  std::vector<int> finished;
  std::vector<char> seen(n, 0);
  for (int s = 0; s < n; ++s) {
    if (seen[s]) continue;
    std::vector<std::pair<int, size_t>> stack{{s, 0}};
    seen[s] = 1;
    while (!stack.empty()) {
      auto& [x, next] = stack.back();
      if (next < out[x].size()) {
        const int y = out[x][next++];
        if (!seen[y]) seen[y] = 1, stack.push_back({y, 0});
      } else {
        finished.push_back(x);
        stack.pop_back();
      }
    }
  }
  LaneGraphComponents c;
  c.strong_of.assign(n, -1);
  int count = 0;
  for (auto it = finished.rbegin(); it != finished.rend(); ++it) {
    if (c.strong_of[*it] >= 0) continue;
    std::vector<int> stack{*it};
    c.strong_of[*it] = count;
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      for (int y : in[x])
        if (c.strong_of[y] < 0) c.strong_of[y] = count, stack.push_back(y);
    }
    ++count;
  }
  rank_components(c.strong_of, c.strong_sizes);

  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto join = [&](int a, int b) { parent[find_root(parent, a)] = find_root(parent, b); };
  for (int i = 0; i < n; ++i) {
    for (LaneGraphNodeId s : graph.nodes[i].successors) join(i, s);
    if (graph.nodes[i].left) join(i, *graph.nodes[i].left);
    if (graph.nodes[i].right) join(i, *graph.nodes[i].right);
  }
  std::map<int, int> root_label;
  c.weak_of.resize(n);
  for (int i = 0; i < n; ++i)
    c.weak_of[i] = root_label.emplace(find_root(parent, i), static_cast<int>(root_label.size())).first->second;
  rank_components(c.weak_of, c.weak_sizes);
  return c;
}

std::string describe_components(const LaneGraphComponents& components) {
  const auto sizes = [](const std::vector<int>& s) {
    std::ostringstream text;
    for (size_t i = 0; i < s.size() && i < 10; ++i) text << (i ? ", " : "") << s[i];
    if (s.size() > 10) text << ", ...";
    return text.str();
  };
  std::ostringstream text;
  text << components.strong_of.size() << " nodes; " << components.strong_sizes.size()
       << " strongly connected components (sizes " << sizes(components.strong_sizes) << "); "
       << components.weak_sizes.size() << " weakly connected (sizes " << sizes(components.weak_sizes) << ")";
  return text.str();
}

std::vector<LaneGraphNodeId> reachable_from(const LaneGraph& graph, LaneGraphNodeId start) {
  if (start < 0 || static_cast<size_t>(start) >= graph.nodes.size()) return {};
  std::vector<char> seen(graph.nodes.size(), 0);
  std::vector<LaneGraphNodeId> stack{start}, out;
  seen[start] = 1;
  while (!stack.empty()) {
    const LaneGraphNodeId x = stack.back();
    stack.pop_back();
    out.push_back(x);
    for (const Edge& e : drivable_edges(graph.nodes[x]))
      if (!seen[e.to]) seen[e.to] = 1, stack.push_back(e.to);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace lidarloop
