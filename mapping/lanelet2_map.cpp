#include "mapping/lanelet2_map.hpp"

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <osmium/builder/attr.hpp>
#include <osmium/io/header.hpp>
#include <osmium/io/writer.hpp>
#include <osmium/io/xml_output.hpp>
#include <osmium/memory/buffer.hpp>

#include "common/input_error.hpp"
#include "localizer/map_files.hpp"
#include "sim/curb_band.hpp"
#include "sim/path.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {

namespace {

namespace attr = osmium::builder::attr;
using Tags = std::vector<std::pair<std::string, std::string>>;
using Member = attr::member_type;

// Autoware's crosswalk module stops this far before a crosswalk that has no stop line
// (autoware_behavior_velocity_crosswalk_module, crosswalk.param.yaml: stop_distance_from_crosswalk 3.5 m):
// a derived stop line goes where Autoware would stop anyway.
constexpr double kDerivedStopDistance = 3.5;
// A stop line of the world at most this far before a crosswalk's near edge is that crosswalk's: the
// campus paints them 4 m before; farther ones serve a junction.
constexpr double kCrosswalkStopLineReach = 10.0;
constexpr size_t kInitialBufferBytes = size_t(1) << 20;  // libosmium buffers grow from here

// One OSM document under construction. In Lanelet2 "everything that has an ID is unique across the
// whole map" (lanelet2_core/doc/Architecture.md), so every object takes the next id of one counter.
// Nodes at the same place are one node, so bounds that meet share their ends: that is how Lanelet2
// finds a lane's successor (lanelet2_core geometry::follows compares the bounds' end points).
class OsmDocument {
 public:
  OsmDocument(const Geodetic& origin, GroundHeight height) : frame_(origin), height_(std::move(height)) {}

  int64_t way(const Polyline2d& line, const Tags& tags) {
    std::vector<osmium::object_id_type> refs;
    for (const Eigen::Vector2d& p : line)
      if (const int64_t id = node(p); refs.empty() || refs.back() != id) refs.push_back(id);
    const int64_t id = next_id_++;
    osmium::builder::add_way(ways_, attr::_id(id), attr::_version(1), attr::_nodes(refs), attr::_tags(tags));
    return id;
  }

  int64_t relation(const std::vector<Member>& members, const Tags& tags) {
    const int64_t id = next_id_++;
    osmium::builder::add_relation(relations_, attr::_id(id), attr::_version(1), attr::_members(members),
                                  attr::_tags(tags));
    return id;
  }

  size_t nodes() const { return node_ids_.size(); }

  void write(const std::string& path) {
    osmium::io::Header header;
    header.set("generator", "lidarloop");
    try {
      osmium::io::Writer writer(osmium::io::File(path, "osm"), header, osmium::io::overwrite::allow);
      // Nodes, then ways, then relations: the order of an OSM file (JOSM reads no other).
      writer(std::move(nodes_));
      writer(std::move(ways_));
      writer(std::move(relations_));
      writer.close();
    } catch (const std::exception& e) {
      throw InputError(path + ": cannot write the Lanelet2 map (" + e.what() + ")");
    }
  }

 private:
  int64_t node(const Eigen::Vector2d& p) {
    const auto [it, added] = node_ids_.try_emplace({p.x(), p.y()}, next_id_);
    if (!added) return it->second;
    const Geodetic g = frame_.to_geodetic(p);
    // local_x/local_y: Autoware's "Local Coordinate Expression" (lanelet2_format_extension.md), what its
    // map loader uses with projector_type Local; ele on every node is mandatory for Autoware (same file,
    // "Elevation Tags").
    const Tags tags = {{"local_x", shortest_decimal(p.x())},
                       {"local_y", shortest_decimal(p.y())},
                       {"ele", shortest_decimal(height_(p))}};
    osmium::builder::add_node(nodes_, attr::_id(next_id_), attr::_version(1),
                              attr::_location(osmium::Location(g.lon_deg, g.lat_deg)), attr::_tags(tags));
    return next_id_++;
  }

  LocalFrame frame_;
  GroundHeight height_;
  int64_t next_id_ = 1;
  std::map<std::pair<double, double>, int64_t> node_ids_;
  osmium::memory::Buffer nodes_{kInitialBufferBytes, osmium::memory::Buffer::auto_grow::yes};
  osmium::memory::Buffer ways_{kInitialBufferBytes, osmium::memory::Buffer::auto_grow::yes};
  osmium::memory::Buffer relations_{kInitialBufferBytes, osmium::memory::Buffer::auto_grow::yes};
};

// Lanelet2 LinestringTagging.md: a lane marking is line_thin with its style as subtype (dashed allows
// a lane change, solid does not); no marking is a virtual line; the end of the carriageway road_border.
Tags divider_tags(MarkingStyle style) {
  if (style == MarkingStyle::none) return {{"type", "virtual"}};
  return {{"type", "line_thin"}, {"subtype", style == MarkingStyle::dashed ? "dashed" : "solid"}};
}

// A stretch of a road between two vertices of its (cut) centreline: lanelets are cut where the road's
// edges open into another road's carriageway (a junction's mouth) and where they close again.
struct Piece {
  size_t first, last;                          // centreline vertex indices
  double s0, s1;                               // their arc lengths
  bool open_right = false, open_left = false;  // the edge runs across another road's carriageway
};

// Junction mouths are found by probing this far beyond the carriageway's edge every kMouthStep along
// the road: past the edge is curb unless another road's carriageway is there. 0.5 m is beyond the
// rounding of the carriageway's outline; the mouth's ends are placed to kMouthStep.
constexpr double kMouthProbe = 0.5, kMouthStep = 0.5;

// The point `offset` metres left of a road's centreline (right if negative) at arc length s.
Eigen::Vector2d beside(const RoadSpec& road, double s, double offset) {
  const PolylineSample at = sample_polyline(road.centreline, s);
  return at.point + Eigen::Vector2d(-at.tangent.y(), at.tangent.x()) * offset;
}

bool edge_open(const RoadSpec& road, const region::Paths& carriageway, double s, double side) {
  return region::contains(carriageway, beside(road, s, side * (road.width / 2 + kMouthProbe)));
}

// The road's centreline with a vertex added at every cut (arc lengths, sorted, inside the line; a vertex
// on a straight stretch leaves every offset line as it was), and the pieces between the cuts.
std::pair<Polyline2d, std::vector<Piece>> cut_road(const RoadSpec& road, const region::Paths& carriageway) {
  const Polyline2d& c = road.centreline;
  const double length = polyline_length(c);
  std::vector<double> cuts;
  auto state = [&](double s) {
    return std::pair{edge_open(road, carriageway, s, -1), edge_open(road, carriageway, s, 1)};
  };
  for (double s = kMouthStep; s <= length; s += kMouthStep)
    if (state(s) != state(s - kMouthStep)) cuts.push_back(s - kMouthStep / 2);
  // A closed road without junctions is cut half way round: a lanelet that is its own successor has no
  // start, and Lanelet2's routing graph cannot order it.
  if (road.closed && cuts.empty()) {
    cuts.push_back(length / 2);
  }
  // A cut this close to a vertex is at the vertex: no segment of zero length, whose normal is undefined.
  constexpr double kSameArc = 1e-6;
  Polyline2d line{c.front()};
  std::vector<size_t> at{0};
  std::vector<double> arc{0};
  double s0 = 0;
  size_t next = 0;
  for (size_t i = 1; i < c.size(); ++i) {
    const double s1 = s0 + (c[i] - c[i - 1]).norm();
    for (; next < cuts.size() && cuts[next] < s1 - kSameArc; ++next) {
      if (cuts[next] <= arc.back() + kSameArc) continue;  // a cut made already
      if (cuts[next] > s0 + kSameArc) line.push_back(c[i - 1] + (c[i] - c[i - 1]) * ((cuts[next] - s0) / (s1 - s0)));
      if (at.back() == line.size() - 1) continue;
      at.push_back(line.size() - 1);
      arc.push_back(std::max(cuts[next], s0));
    }
    line.push_back(c[i]);
    s0 = s1;
  }
  at.push_back(line.size() - 1);
  arc.push_back(s0);
  std::vector<Piece> pieces;
  for (size_t k = 0; k + 1 < at.size(); ++k) {
    const auto [right, left] = state((arc[k] + arc[k + 1]) / 2);
    pieces.push_back({at[k], at[k + 1], arc[k], arc[k + 1], right, left});
  }
  return {line, pieces};
}

// Signed arc length from a to b along the road (the short way round on a closed road).
double along(const RoadSpec& road, double a, double b) {
  double d = b - a;
  if (road.closed) {
    const double length = polyline_length(road.centreline);
    d = std::remainder(d, length);
  }
  return d;
}

// A line across the carriageway at arc length s (round a closed road's start if past it), from `from` to
// `to` (lateral offsets, left positive).
Polyline2d across(const RoadSpec& road, double s, double from, double to) {
  if (road.closed) {
    const double length = polyline_length(road.centreline);
    s -= length * std::floor(s / length);
  }
  return {beside(road, s, from), beside(road, s, to)};
}

// Lateral extent of the carriageway's half that traffic in a direction uses.
std::pair<double, double> travel_half(const RoadSpec& road, bool backward) {
  const double half = road.width / 2;
  if (road.one_way) return {-half, half};
  return backward ? std::pair{0.0, half} : std::pair{-half, 0.0};
}

struct StopLine {
  const RoadSpec* road;
  double s;
  RoadSide side;
  int64_t way;
};

class MapBuilder {
 public:
  MapBuilder(const WorldDescription& world, const World& built, const SurveyedLine& surveyed)
      : world_(world), carriageway_(built.carriageway), surveyed_(surveyed), osm_(world.origin, built.pavement()) {}

  void curbs(const CurbMap& curbs) {
    for (size_t i = 0; i < curbs.curbs.size(); ++i) {
      // A map that does not say what its curbs are: taken as barrier curbs, which nothing drives over.
      const std::string kind = i < curbs.kinds.size() ? curbs.kinds[i] : curb_profile_name(CurbProfile::vertical);
      osm_.way(curbs.curbs[i], {{"type", "curbstone"}, {"subtype", curbstone_subtype(kind)}});
      ++summary_.curbstones;
    }
  }

  void stop_lines() {
    for (const StopLineSpec& spec : world_.stop_lines) {
      const RoadSpec& road = *world_.road(spec.road);
      const double half = road.width / 2;
      const double from = spec.side == RoadSide::left ? 0.0 : -half, to = spec.side == RoadSide::right ? 0.0 : half;
      stop_lines_.push_back({&road, spec.at, spec.side, line(across(road, spec.at, from, to), stop_line_tags())});
      ++summary_.stop_lines;
    }
  }

  // Autoware's crosswalk (vector map requirement vm-05-01; extra_regulatory_elements.md, "Crosswalk"): a
  // lanelet subtype=crosswalk, a crosswalk_polygon over the carriageway, stop lines before it, and a
  // regulatory element subtype=crosswalk that refers to the lanelet and names the polygon and the stop
  // lines (ref_line); the road's lanelets list the regulatory element (road_lanes does that).
  void crosswalks() {
    for (const CrosswalkSpec& cw : world_.crosswalks) {
      const RoadSpec& road = *world_.road(cw.road);
      const double half = road.width / 2, w = cw.width / 2;
      // The pedestrians' line, right sidewalk to left (sim/path.hpp), widened to the crosswalk's width.
      const Path walk = crosswalk_path(road, cw, false);
      const Eigen::Vector2d t = sample_polyline(road.centreline, cw.at).tangent;
      const Eigen::Vector2d a = walk.points.front(), b = walk.points.back();
      // Walking from the right side to the left, the side towards lower arc length is on the left.
      const int64_t left = line({a - t * w, b - t * w}, {{"type", "pedestrian_marking"}});
      const int64_t right = line({a + t * w, b + t * w}, {{"type", "pedestrian_marking"}});
      // Crosswalk lanelets are two-way and for pedestrians (Lanelet2 LaneletAndAreaTagging.md).
      const int64_t lanelet =
          osm_.relation({Member(osmium::item_type::way, left, "left"), Member(osmium::item_type::way, right, "right")},
                        {{"type", "lanelet"},
                         {"subtype", "crosswalk"},
                         {"location", "urban"},
                         {"one_way", "no"},
                         {"participant:pedestrian", "yes"}});
      // An OSM polygon is a way tagged area=yes whose last node is not repeated (Lanelet2 OSM format;
      // Autoware's examples of area ways in lanelet2_format_extension.md).
      const Polyline2d poly = across(road, cw.at - cw.width / 2, -half, half);
      const Polyline2d far = across(road, cw.at + cw.width / 2, half, -half);
      const int64_t polygon =
          line({poly[0], poly[1], far[0], far[1]}, {{"type", "crosswalk_polygon"}, {"area", "yes"}});
      std::vector<Member> members = {Member(osmium::item_type::relation, lanelet, "refers"),
                                     Member(osmium::item_type::way, polygon, "crosswalk_polygon")};
      for (const bool backward : {false, true}) {
        if (backward && road.one_way) continue;
        members.emplace_back(osmium::item_type::way, stop_line_for(road, cw, backward), "ref_line");
      }
      const int64_t regulatory = osm_.relation(members, {{"type", "regulatory_element"}, {"subtype", "crosswalk"}});
      crosswalk_elements_.push_back({&cw, regulatory});
      ++summary_.crosswalks;
    }
  }

  // Autoware's road lanelets (vm-01-01): subtype=road, location=urban, one_way=yes, speed_limit in km/h.
  // Bounds are left and right of the direction of travel; Lanelet2's loader orients the two bounds by
  // geometry (lanelet2_io OsmHandlerLoad.cpp: geometry::align), so a shared divider is one way. Where an
  // edge opens into another road the bound is virtual (LinestringTagging.md: "mainly for intersections")
  // and the lanelet, in the intersection, goes straight on (Autoware vm-03-02: every lanelet in an
  // intersection has a turn_direction).
  void road_lanes() {
    for (const RoadSpec& road : world_.roads) {
      const double lane_width = road.width / road.lanes;
      const auto [centreline, pieces] = cut_road(road, carriageway_);
      // bounds[k][p]: the line k lanes from the right curb over piece p.
      std::vector<std::vector<int64_t>> bounds(size_t(road.lanes) + 1);
      for (int k = 0; k <= road.lanes; ++k) {
        const Polyline2d offset = offset_polyline(centreline, -road.width / 2 + k * lane_width, road.closed);
        for (const Piece& p : pieces) {
          const bool edge = k == 0 || k == road.lanes, open = k == 0 ? p.open_right : p.open_left;
          const Tags tags = !edge  ? divider_tags(road.marking)
                            : open ? Tags{{"type", "virtual"}}
                                   : Tags{{"type", "road_border"}};
          bounds[size_t(k)].push_back(
              line(Polyline2d(offset.begin() + long(p.first), offset.begin() + long(p.last) + 1), tags));
        }
      }
      for (int j = 0; j < road.lanes; ++j) {
        const double centre = -road.width / 2 + (j + 0.5) * lane_width;
        // Right-hand traffic: on a two-way road the lanes right of the centreline go along it; a lane on
        // the centreline (one lane for both directions) is two-way.
        const bool two_way = !road.one_way && std::abs(centre) < 1e-9;
        const bool backward = !road.one_way && centre > 1e-9;
        for (size_t p = 0; p < pieces.size(); ++p) {
          const int64_t right_line = bounds[size_t(backward ? j + 1 : j)][p];
          const int64_t left_line = bounds[size_t(backward ? j : j + 1)][p];
          std::vector<Member> members = {Member(osmium::item_type::way, left_line, "left"),
                                         Member(osmium::item_type::way, right_line, "right")};
          for (const auto& [cw, regulatory] : crosswalk_elements_)
            if (cw->road == road.name && crosses(road, pieces[p], *cw))
              members.emplace_back(osmium::item_type::relation, regulatory, "regulatory_element");
          Tags tags = {{"type", "lanelet"},
                       {"subtype", "road"},
                       {"location", "urban"},
                       {"one_way", two_way ? "no" : "yes"},
                       {"speed_limit", shortest_decimal(road.design_speed)},
                       {"participant:vehicle", "yes"}};
          if (pieces[p].open_right || pieces[p].open_left) {
            tags.emplace_back("turn_direction", "straight");
            ++summary_.intersection_lanelets;
          }
          osm_.relation(members, tags);
          ++summary_.road_lanelets;
        }
      }
    }
  }

  Lanelet2Summary write(const std::string& path) {
    osm_.write(path);
    summary_.nodes = osm_.nodes();
    return summary_;
  }

 private:
  static Tags stop_line_tags() { return {{"type", "stop_line"}}; }

  // A line of the world, where the survey put it.
  int64_t line(const Polyline2d& world_line, const Tags& tags) { return osm_.way(surveyed_(world_line), tags); }

  static bool crosses(const RoadSpec& road, const Piece& piece, const CrosswalkSpec& cw) {
    return along(road, piece.s0, cw.at + cw.width / 2) >= 0 && along(road, cw.at - cw.width / 2, piece.s1) >= 0;
  }

  // The world's stop line for traffic approaching the crosswalk in this direction, or one derived
  // kDerivedStopDistance before the crosswalk.
  int64_t stop_line_for(const RoadSpec& road, const CrosswalkSpec& cw, bool backward) {
    const RoadSide half = backward ? RoadSide::left : RoadSide::right;
    const double edge = backward ? cw.at + cw.width / 2 : cw.at - cw.width / 2;
    for (const StopLine& s : stop_lines_) {
      if (s.road != &road || (s.side != half && s.side != RoadSide::both)) continue;
      const double before = backward ? along(road, edge, s.s) : along(road, s.s, edge);
      if (before >= 0 && before <= kCrosswalkStopLineReach) return s.way;
    }
    const double s = backward ? edge + kDerivedStopDistance : edge - kDerivedStopDistance;
    const auto [from, to] = travel_half(road, backward);
    ++summary_.derived_stop_lines;
    return line(across(road, s, from, to), stop_line_tags());
  }

  const WorldDescription& world_;
  const region::Paths& carriageway_;
  const SurveyedLine& surveyed_;
  OsmDocument osm_;
  Lanelet2Summary summary_;
  std::vector<StopLine> stop_lines_;
  std::vector<std::pair<const CrosswalkSpec*, int64_t>> crosswalk_elements_;
};

}  // namespace

const char* curbstone_subtype(const std::string& kind) {
  // Lanelet2 LinestringTagging.md: `high` is too high for a vehicle to drive over, `low` can be driven
  // over. A vertical (barrier) curb is high; sloped and rolled curbs are mountable (AASHTO 4.7) and a cut
  // is level with the road, so they are low.
  return kind == curb_profile_name(CurbProfile::vertical) ? "high" : "low";
}

Lanelet2Summary write_lanelet2_map(const std::string& path, const WorldDescription& world, const World& built,
                                   const CurbMap& curbs, const SurveyedLine& surveyed) {
  MapBuilder builder(world, built, surveyed);
  builder.curbs(curbs);
  builder.stop_lines();
  builder.crosswalks();  // before the lanes, which list the crosswalks' regulatory elements
  builder.road_lanes();
  return builder.write(path);
}

}  // namespace lidarloop
