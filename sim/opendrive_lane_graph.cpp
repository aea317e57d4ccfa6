#include "sim/opendrive_lane_graph.hpp"

#include <algorithm>
#include <cmath>

#include "common/input_error.hpp"
#include "sim/opendrive_geometry.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kJoin = 1.0;          // m: a successor starts this near its predecessor's end
constexpr double kMinWidth = 0.5;      // m: narrower lanes (a lane opening or closing) are not driven
constexpr double kShortSection = 0.1;  // m: shorter lane sections are not nodes

bool drivable(const OdrLane& lane) {
  static const char* kTypes[] = {"driving", "bidirectional", "entry",          "exit",
                                 "onRamp",  "offRamp",       "connectingRamp", "slipLane"};
  return std::any_of(std::begin(kTypes), std::end(kTypes), [&](const char* t) { return lane.type == t; });
}

// Whether a car in lane `from` may cross `lane`'s mark (on its outer edge) into lane `to`: as the mark's
// laneChange says, else by its type (ASAM OpenDRIVE 1.8 11.8: broken lines; no mark at all).
bool crossable(const OdrLane& lane, int from, int to) {
  if (lane.marks.empty()) return true;
  const OdrRoadMark& m = lane.marks.front();
  if (m.lane_change == "both") return true;
  if (m.lane_change == "none") return false;
  if (m.lane_change == "increase") return to > from;
  if (m.lane_change == "decrease") return to < from;
  return m.type == "broken" || m.type == "broken broken" || m.type == "botts dots" || m.type == "none";
}

struct Builder {
  const OdrMap& map;
  double step;
  OdrLaneGraph out;
  std::map<std::tuple<std::string, size_t, int>, LaneGraphNodeId> node_at;  // road, section, lane

  std::optional<LaneGraphNodeId> node(const std::string& road, size_t section, int lane) const {
    const auto it = node_at.find({road, section, lane});
    return it == node_at.end() ? std::nullopt : std::optional(it->second);
  }

  void nodes() {
    for (const auto& road : map.roads)
      for (size_t i = 0; i < road.sections.size(); ++i) {
        const double s0 = road.sections[i].s, s1 = std::min(road.section_end(i), road.length);
        if (s1 - s0 < kShortSection) continue;
        for (const auto* side : {&road.sections[i].left, &road.sections[i].right})
          for (const auto& lane : *side) {
            if (!drivable(lane)) continue;
            LaneGraphNode n;
            n.lanelet = Lanelet2Id(out.graph.nodes.size());
            n.subtype = "road";
            const int k = std::max(1, int(std::ceil((s1 - s0) / step)));
            double widest = 0;
            for (int j = 0; j <= k; ++j) {
              const double s = s0 + (s1 - s0) * j / k;
              const OdrLaneEdges e = lane_edges(road, i, lane.id, s);
              widest = std::max(widest, std::abs(e.outer - e.inner));
              // Driven along s, the edge at the larger t is on the left.
              const bool inner_on_left = road.along_s(lane.id) == (e.inner > e.outer);
              const double left_t = inner_on_left ? e.inner : e.outer, right_t = inner_on_left ? e.outer : e.inner;
              n.left_bound.push_back(road_point(road, s, left_t).head<2>());
              n.right_bound.push_back(road_point(road, s, right_t).head<2>());
              n.centreline.push_back(road_point(road, s, 0.5 * (e.inner + e.outer)).head<2>());
            }
            if (widest < kMinWidth) continue;
            if (!road.along_s(lane.id))
              for (auto* line : {&n.left_bound, &n.right_bound, &n.centreline})
                std::reverse(line->begin(), line->end());
            n.length = polyline_length(n.centreline);
            const auto id = LaneGraphNodeId(out.graph.nodes.size());
            node_at[{road.id, i, lane.id}] = id;
            out.graph.nodes_of[n.lanelet] = {id};
            out.graph.nodes.push_back(std::move(n));
            out.lane_of.emplace_back(road.id, lane.id);
          }
      }
    // A lane's nodes in driving order.
    for (const auto& road : map.roads)
      for (size_t i = 0; i < road.sections.size(); ++i)
        for (const auto* side : {&road.sections[i].left, &road.sections[i].right})
          for (const auto& lane : *side)
            if (const auto n = node(road.id, i, lane.id)) out.nodes_of[{road.id, lane.id}].push_back(*n);
    for (auto& [ref, ids] : out.nodes_of)
      if (!map.road(ref.first)->along_s(ref.second)) std::reverse(ids.begin(), ids.end());
  }

  void connect(LaneGraphNodeId from, std::optional<LaneGraphNodeId> to) {
    if (!to || *to == from) return;
    LaneGraphNode& a = out.graph.nodes[size_t(from)];
    const LaneGraphNode& b = out.graph.nodes[size_t(*to)];
    if ((a.centreline.back() - b.centreline.front()).norm() > kJoin) return;
    if (std::find(a.successors.begin(), a.successors.end(), *to) == a.successors.end()) a.successors.push_back(*to);
  }

  // The node at the end of `road` given by a contact point, for lane `lane`: in the section there, or
  // the next one in where that section is too short to drive (editors leave sections of centimetres).
  std::optional<LaneGraphNodeId> at_contact(const OdrRoad& road, const std::string& contact, int lane) const {
    const size_t n = road.sections.size();
    for (size_t k = 0; k < n; ++k) {
      const size_t i = contact == "end" ? n - 1 - k : k;
      if (road.section_end(i) - road.sections[i].s >= kShortSection) return node(road.id, i, lane);
    }
    return std::nullopt;
  }

  void edges() {
    for (const auto& road : map.roads)
      for (size_t i = 0; i < road.sections.size(); ++i)
        for (const auto* side : {&road.sections[i].left, &road.sections[i].right})
          for (const auto& lane : *side) {
            const auto self = node(road.id, i, lane.id);
            if (!self) continue;
            const bool forward = road.along_s(lane.id);
            // The next section long enough to drive, in the direction of travel, following the lane
            // links through the short ones between (editors leave sections of centimetres); at the
            // road's end, the lane there and its link onwards.
            int cur = lane.id;
            std::optional<int> onward = forward ? lane.successor : lane.predecessor;
            std::optional<size_t> next;
            bool lost = false;
            for (size_t k = forward ? i + 1 : i; forward ? k < road.sections.size() : k > 0; forward ? ++k : --k) {
              const size_t at = forward ? k : k - 1;
              const int id = onward.value_or(cur);
              if (road.section_end(at) - road.sections[at].s >= kShortSection) {
                next = at, cur = id;
                break;
              }
              const OdrLane* through = road.sections[at].lane(id);
              if (!through) {
                lost = true;
                break;
              }
              cur = id;
              onward = forward ? through->successor : through->predecessor;
            }
            if (next) {
              connect(*self, node(road.id, *next, cur));
            } else if (const auto& rl = forward ? road.successor : road.predecessor; rl && !lost) {
              if (rl->element_type == "road") {
                if (const OdrRoad* other = map.road(rl->element_id); other && onward)
                  connect(*self, at_contact(*other, rl->contact_point, *onward));
              } else {
                for (const auto& j : map.junctions) {
                  if (j.id != rl->element_id) continue;
                  for (const auto& c : j.connections) {
                    if (c.incoming_road != road.id) continue;
                    const OdrRoad* via = map.road(c.connecting_road);
                    for (const auto& ll : c.lane_links)
                      if (via && ll.from == cur) connect(*self, at_contact(*via, c.contact_point, ll.to));
                  }
                }
              }
            }
            // Neighbours: driven along s, the lane at the next smaller t (id - 1) is on the right. The
            // centre (id 0) is never crossed: the lanes beyond it go the other way. A lane change
            // crosses the mark on the outer edge of the lane nearer the centre.
            LaneGraphNode& n = out.graph.nodes[size_t(*self)];
            const int right = forward ? lane.id - 1 : lane.id + 1, left = forward ? lane.id + 1 : lane.id - 1;
            auto mark_between = [&](int other) -> const OdrLane& {
              return std::abs(other) < std::abs(lane.id) ? *road.sections[i].lane(other) : lane;
            };
            if (right != 0)
              if (const auto r = node(road.id, i, right))
                n.right = *r, n.can_change_right = crossable(mark_between(right), lane.id, right);
            if (left != 0)
              if (const auto l = node(road.id, i, left))
                n.left = *l, n.can_change_left = crossable(mark_between(left), lane.id, left);
          }
  }
};

}  // namespace

OdrLaneGraph build_opendrive_lane_graph(const OdrMap& map, double step) {
  Builder b{map, step, {}, {}};
  b.nodes();
  b.edges();
  return std::move(b.out);
}

std::vector<LaneGraphNodeId> route_from_opendrive_lanes(const OdrLaneGraph& graph,
                                                        const std::vector<OdrLaneRef>& lanes) {
  std::vector<LaneGraphNodeId> route;
  auto name = [](const OdrLaneRef& l) { return "[" + l.first + ", " + std::to_string(l.second) + "]"; };
  for (size_t k = 0; k < lanes.size(); ++k) {
    const auto it = graph.nodes_of.find(lanes[k]);
    if (it == graph.nodes_of.end())
      throw InputError("lane " + name(lanes[k]) + " is not a driving lane of the map (road id, lane id)");
    if (!route.empty()) {
      const LaneGraphNode& last = graph.graph.nodes[size_t(route.back())];
      const LaneGraphNodeId first = it->second.front();
      const bool follows = std::find(last.successors.begin(), last.successors.end(), first) != last.successors.end();
      const bool beside =
          (last.left == first && last.can_change_left) || (last.right == first && last.can_change_right);
      if (!follows && !beside)
        throw InputError("lane " + name(lanes[k]) + " does not follow lane " + name(lanes[k - 1]) +
                         " (neither its successor nor a neighbour it may change into)");
    }
    route.insert(route.end(), it->second.begin(), it->second.end());
  }
  return route;
}

}  // namespace lidarloop
