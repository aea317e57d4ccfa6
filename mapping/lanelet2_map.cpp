#include "mapping/lanelet2_map.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include <pugixml.hpp>

#include "common/input_error.hpp"
#include "localizer/map_files.hpp"
#include "sim/curb_band.hpp"
#include "sim/path.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {

namespace {

using Tags = std::vector<std::pair<std::string, std::string>>;

// A relation's member: its OSM type ("way", "relation"), id and role.
struct Member {
  const char* type;
  int64_t ref;
  std::string role;
};
Member way_member(int64_t id, const std::string& role) { return {"way", id, role}; }
Member relation_member(int64_t id, const std::string& role) { return {"relation", id, role}; }

// Autoware's crosswalk module stops this far before a crosswalk that has no stop line
// (autoware_behavior_velocity_crosswalk_module, crosswalk.param.yaml: stop_distance_from_crosswalk 3.5 m):
// a derived stop line goes where Autoware would stop anyway.
constexpr double kDerivedStopDistance = 3.5;
// A stop line of the world at most this far before a crosswalk's near edge is that crosswalk's: the
// campus paints them 4 m before; farther ones serve a junction.
constexpr double kCrosswalkStopLineReach = 10.0;

// One OSM document under construction. In Lanelet2 "everything that has an ID is unique across the
// whole map" (lanelet2_core/doc/Architecture.md), so every object takes the next id of one counter.
// Nodes at the same place are one node, so bounds that meet share their ends: that is how Lanelet2
// finds a lane's successor (lanelet2_core geometry::follows compares the bounds' end points).
class OsmDocument {
 public:
  OsmDocument(const Geodetic& origin, GroundHeight height)
      : frame_(origin), origin_(origin), height_(std::move(height)) {}

  int64_t way(const Polyline2d& line, const Tags& tags) {
    std::vector<int64_t> refs;
    for (const Eigen::Vector2d& p : line)
      if (const int64_t id = node(p); refs.empty() || refs.back() != id) refs.push_back(id);
    ways_.push_back({next_id_, std::move(refs), tags});
    return next_id_++;
  }

  int64_t relation(const std::vector<Member>& members, const Tags& tags) {
    relations_.push_back({next_id_, members, tags});
    return next_id_++;
  }

  size_t nodes() const { return nodes_.size(); }

  // The file, written with pugixml (the XML library sim/lanelet2_file.cpp reads it with).
  void write(const std::string& path, const std::string& map_version) const {
    pugi::xml_document doc;
    pugi::xml_node declaration = doc.append_child(pugi::node_declaration);
    declaration.append_attribute("version") = "1.0";
    declaration.append_attribute("encoding") = "UTF-8";
    pugi::xml_node osm = doc.append_child("osm");
    osm.append_attribute("version") = "0.6";
    osm.append_attribute("generator") = "lidarloop";
    // Autoware's map loader checks the map's format version (autoware_lanelet2_extension
    // lanelet2_format_extension.md, "Meta Info": a MetaInfo element beside the nodes, ways and
    // relations, `<MetaInfo format_version='1.0' map_version='1.0'/>` in its example; autoware.universe
    // PR 7074 rejects maps of an unsupported format_version). This map uses the format's first version's
    // elements only.
    pugi::xml_node meta = osm.append_child("MetaInfo");
    meta.append_attribute("format_version") = "1.0";
    meta.append_attribute("map_version") = map_version.c_str();
    auto add_tags = [](pugi::xml_node element, const Tags& tags) {
      for (const auto& [k, v] : tags) {
        pugi::xml_node tag = element.append_child("tag");
        tag.append_attribute("k") = k.c_str();
        tag.append_attribute("v") = v.c_str();
      }
    };
    // Nodes, then ways, then relations: the order of an OSM file (JOSM reads no other).
    for (const Node& n : nodes_) {
      pugi::xml_node e = osm.append_child("node");
      e.append_attribute("id") = std::to_string(n.id).c_str();
      e.append_attribute("version") = "1";
      // lat / lon as the shortest decimals that read back to the same doubles: finer than OSM's 1e-7
      // degrees (1.1 cm), so lat / lon and local_x / local_y agree to well under a millimetre.
      e.append_attribute("lat") = shortest_decimal(n.geodetic.lat_deg).c_str();
      e.append_attribute("lon") = shortest_decimal(n.geodetic.lon_deg).c_str();
      // local_x/local_y: Autoware's "Local Coordinate Expression" (lanelet2_format_extension.md), what
      // its map loader uses with projector_type Local; ele on every node is mandatory for Autoware (same
      // file, "Elevation Tags").
      add_tags(e, {{"local_x", shortest_decimal(n.local.x())},
                   {"local_y", shortest_decimal(n.local.y())},
                   {"ele", shortest_decimal(n.ele)}});
    }
    for (const Way& w : ways_) {
      pugi::xml_node e = osm.append_child("way");
      e.append_attribute("id") = std::to_string(w.id).c_str();
      e.append_attribute("version") = "1";
      for (const int64_t ref : w.refs) e.append_child("nd").append_attribute("ref") = std::to_string(ref).c_str();
      add_tags(e, w.tags);
    }
    for (const Relation& r : relations_) {
      pugi::xml_node e = osm.append_child("relation");
      e.append_attribute("id") = std::to_string(r.id).c_str();
      e.append_attribute("version") = "1";
      for (const Member& m : r.members) {
        pugi::xml_node member = e.append_child("member");
        member.append_attribute("type") = m.type;
        member.append_attribute("ref") = std::to_string(m.ref).c_str();
        member.append_attribute("role") = m.role.c_str();
      }
      add_tags(e, r.tags);
    }
    std::ostringstream text;
    doc.save(text, "  ", pugi::format_default, pugi::encoding_utf8);
    try {
      write_file_atomically(path, text.str());
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(path + ": cannot write the Lanelet2 map (" + e.what() + ")");
    }
  }

 private:
  struct Node {
    int64_t id;
    Eigen::Vector2d local;
    Geodetic geodetic;
    double ele;
  };
  struct Way {
    int64_t id;
    std::vector<int64_t> refs;
    Tags tags;
  };
  struct Relation {
    int64_t id;
    std::vector<Member> members;
    Tags tags;
  };

  int64_t node(const Eigen::Vector2d& p) {
    const auto [it, added] = node_ids_.try_emplace({p.x(), p.y()}, next_id_);
    if (!added) return it->second;
    // ele: the WGS-84 ellipsoidal height map_projector_info.yaml declares (vertical_datum: WGS84), the
    // origin's altitude plus the pavement's height in the local frame. Autoware puts the GNSS altitude in
    // the map frame's z (autoware_geography_utils project_forward), so heights above the origin would
    // put the car the origin's altitude off the map.
    const double ele = origin_.alt_m + height_(p);
    nodes_.push_back({next_id_, p, frame_.to_geodetic(p), ele});
    return next_id_++;
  }

  LocalFrame frame_;
  Geodetic origin_;
  GroundHeight height_;
  int64_t next_id_ = 1;
  std::map<std::pair<double, double>, int64_t> node_ids_;
  std::vector<Node> nodes_;
  std::vector<Way> ways_;
  std::vector<Relation> relations_;
};

// Lane bounds carry Lanelet2's `lane_change` tag (LinestringTagging.md: it overrides what the line's type
// implies), which Autoware's lanelet2_format_extension asks for on lane bounds: a dashed line may be
// crossed, a solid one not. Lanelet2 LinestringTagging.md: a lane marking is line_thin with its style as
// subtype; no marking is a virtual line, which a car may cross between lanes.
Tags divider_tags(MarkingStyle style) {
  if (style == MarkingStyle::none) return {{"type", "virtual"}, {"lane_change", "yes"}};
  const bool dashed = style == MarkingStyle::dashed;
  return {{"type", "line_thin"}, {"subtype", dashed ? "dashed" : "solid"}, {"lane_change", dashed ? "yes" : "no"}};
}
// The end of the carriageway (LinestringTagging.md road_border): nothing crosses it.
Tags border_tags() { return {{"type", "road_border"}, {"lane_change", "no"}}; }
// Lines in a junction are virtual ("mainly for intersections", LinestringTagging.md); Autoware changes
// no lane in an intersection (its lane change module plans none there), so they say no.
Tags junction_line_tags() { return {{"type", "virtual"}, {"lane_change", "no"}}; }

// Junction mouths are found by probing this far beyond the carriageway's edge every kMouthStep along
// the road: past the edge is curb unless another road's carriageway is there. 0.5 m is beyond the
// rounding of the carriageway's outline; the mouth's ends are placed to kMouthStep.
constexpr double kMouthProbe = 0.5, kMouthStep = 0.5;
// Centrelines meeting within this of each other meet in one junction (three roads ending at one point
// give three crossings a few millimetres apart).
constexpr double kJunctionMerge = 2.0;
// A road's end this close to another road's centreline meets that road (a T-junction's side road).
constexpr double kOnRoad = 0.05;
// A junction's arm ends where both edges of the road are curbed again, looked for up to this far.
constexpr double kMaxMouth = 60;
// A road going on less than this past a junction has no arm there (it ends in the junction).
constexpr double kArmEnd = 1.0;
// Lanelets between junctions shorter than this are counted as slivers (Autoware's convention is a
// lanelet of 1-50 m, AutowareLanelet2Format "Lane length"; a junction mouth should leave no 1.5 m ones).
constexpr double kMinLanelet = 3.0;
// A movement turning by less than this is straight on, by more than kMaxTurn a U-turn (not made).
constexpr double kStraightWithin = 45 * std::numbers::pi / 180, kMaxTurn = 150 * std::numbers::pi / 180;
constexpr double kCurveStep = 1.0;  // spacing of a connecting lanelet's bound points, m

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Arc length s brought onto the road: round a closed road, clamped to an open one.
double wrap_arc(const RoadSpec& road, double s) {
  const double length = polyline_length(road.centreline);
  return road.closed ? s - length * std::floor(s / length) : std::clamp(s, 0.0, length);
}

// The point `offset` metres left of a road's centreline (right if negative) at arc length s.
Eigen::Vector2d beside(const RoadSpec& road, double s, double offset) {
  const PolylineSample at = sample_polyline(road.centreline, wrap_arc(road, s));
  return at.point + Eigen::Vector2d(-at.tangent.y(), at.tangent.x()) * offset;
}

bool edge_open(const RoadSpec& road, const region::Paths& carriageway, double s, double side) {
  return region::contains(carriageway, beside(road, s, side * (road.width / 2 + kMouthProbe)));
}

// Signed arc length from a to b along the road (the short way round on a closed road).
double along(const RoadSpec& road, double a, double b) {
  double d = b - a;
  if (road.closed) d = std::remainder(d, polyline_length(road.centreline));
  return d;
}

// A line across the carriageway at arc length s, from `from` to `to` (lateral offsets, left positive).
Polyline2d across(const RoadSpec& road, double s, double from, double to) {
  return {beside(road, s, from), beside(road, s, to)};
}

// Lateral extent of the carriageway's half that traffic in a direction uses.
std::pair<double, double> travel_half(const RoadSpec& road, bool backward) {
  const double half = road.width / 2;
  if (road.one_way) return {-half, half};
  return backward ? std::pair{0.0, half} : std::pair{-half, 0.0};
}

// Which way lane j (counted from the right curb) of a road runs: +1 along the centreline, -1 against
// it, 0 both ways. Right-hand traffic: on a two-way road the lanes right of the centreline go along it;
// a lane on the centreline (one lane for both directions) is two-way.
int lane_travel(const RoadSpec& road, int j) {
  if (road.one_way) return 1;
  const double centre = -road.width / 2 + (j + 0.5) * road.width / road.lanes;
  if (std::abs(centre) < 1e-9) return 0;
  return centre > 0 ? -1 : 1;
}

struct JunctionRoad {
  size_t road;
  double s;  // arc length of the junction's centre on the road
};
struct Junction {
  std::vector<JunctionRoad> roads;
};

// Where centrelines cross or a road's end lies on another road, grouped into junctions of two or more
// roads.
std::vector<Junction> find_junctions(const std::vector<RoadSpec>& roads) {
  struct Hit {
    size_t road;
    double s;
    Eigen::Vector2d p;
  };
  std::vector<Hit> hits;
  std::vector<size_t> parent;
  auto add = [&](const Hit& a, const Hit& b) {
    hits.push_back(a);
    hits.push_back(b);
    parent.push_back(parent.size());
    parent.push_back(parent.size());
  };
  std::vector<std::vector<double>> arcs(roads.size());
  for (size_t r = 0; r < roads.size(); ++r) {
    arcs[r].push_back(0);
    for (size_t i = 1; i < roads[r].centreline.size(); ++i)
      arcs[r].push_back(arcs[r].back() + (roads[r].centreline[i] - roads[r].centreline[i - 1]).norm());
  }
  for (size_t a = 0; a < roads.size(); ++a)
    for (size_t b = a + 1; b < roads.size(); ++b) {
      const Polyline2d &ca = roads[a].centreline, &cb = roads[b].centreline;
      for (size_t i = 0; i + 1 < ca.size(); ++i)
        for (size_t j = 0; j + 1 < cb.size(); ++j) {
          const Eigen::Vector2d d1 = ca[i + 1] - ca[i], d2 = cb[j + 1] - cb[j], r = cb[j] - ca[i];
          const double den = cross2(d1, d2);
          if (std::abs(den) <= 1e-12 * d1.norm() * d2.norm()) continue;  // parallel: ends are found below
          const double t = cross2(r, d2) / den, u = cross2(r, d1) / den;
          if (t < 0 || t > 1 || u < 0 || u > 1) continue;
          const Eigen::Vector2d p = ca[i] + t * d1;
          add({a, arcs[a][i] + t * d1.norm(), p}, {b, arcs[b][j] + u * d2.norm(), p});
        }
    }
  for (size_t a = 0; a < roads.size(); ++a) {
    if (roads[a].closed) continue;
    for (const double s : {0.0, arcs[a].back()}) {
      const Eigen::Vector2d p = sample_polyline(roads[a].centreline, s).point;
      for (size_t b = 0; b < roads.size(); ++b) {
        if (b == a) continue;
        const double sb = project_onto_polyline(roads[b].centreline, p);
        const Eigen::Vector2d q = sample_polyline(roads[b].centreline, sb).point;
        if ((q - p).norm() <= kOnRoad) add({a, s, p}, {b, sb, q});
      }
    }
  }
  // Union-find: a pair is one junction, and hits close together are one junction.
  std::function<size_t(size_t)> root = [&](size_t i) { return parent[i] == i ? i : parent[i] = root(parent[i]); };
  for (size_t i = 0; i < hits.size(); i += 2) parent[root(i + 1)] = root(i);
  for (size_t i = 0; i < hits.size(); ++i)
    for (size_t j = i + 1; j < hits.size(); ++j)
      if ((hits[i].p - hits[j].p).norm() <= kJunctionMerge) parent[root(j)] = root(i);
  std::map<size_t, Junction> groups;
  for (size_t i = 0; i < hits.size(); ++i) {
    Junction& junction = groups[root(i)];
    const bool known = std::any_of(junction.roads.begin(), junction.roads.end(),
                                   [&](const JunctionRoad& jr) { return jr.road == hits[i].road; });
    if (!known) junction.roads.push_back({hits[i].road, hits[i].s});
  }
  std::vector<Junction> out;
  for (auto& [key, junction] : groups) {
    if (junction.roads.size() < 2) continue;
    std::sort(junction.roads.begin(), junction.roads.end(),
              [](const JunctionRoad& x, const JunctionRoad& y) { return x.road < y.road; });
    out.push_back(std::move(junction));
  }
  return out;
}

// Arc length from a junction's centre at s to its mouth on the road in direction dir: where both edges
// of the road are curbed again (the corners' fillets are part of the junction), or the road's end.
double mouth_distance(const RoadSpec& road, const region::Paths& carriageway, double s, int dir) {
  const double length = polyline_length(road.centreline);
  for (double d = kMouthStep; d <= kMaxMouth; d += kMouthStep) {
    const double at = s + dir * d;
    if (!road.closed && (at <= 0 || at >= length)) return dir > 0 ? length - s : s;
    if (!edge_open(road, carriageway, at, -1) && !edge_open(road, carriageway, at, 1)) return d;
  }
  return kMaxMouth;
}

// One arm of a junction: a road leaving it, up to its mouth.
struct Arm {
  size_t junction = 0, road = 0;
  int dir = 1;  // +1: the arm runs towards higher arc length
  // At the mouth, filled when the road's lanes are written: the points of the lines between lanes,
  // k = 0 (right curb) .. lanes (left curb), exactly the lane bounds' ends; the centreline's direction.
  std::vector<Eigen::Vector2d> points;
  Eigen::Vector2d tangent{1, 0};
};

Arm arm(size_t junction, size_t road, int dir) {
  Arm a;
  a.junction = junction;
  a.road = road;
  a.dir = dir;
  return a;
}

// A junction's stretch of one road, in the road's arc length (lo may be below 0 or hi beyond the
// length on a closed road).
struct Span {
  double lo, hi;
  size_t junction;
  std::optional<size_t> back_arm, forward_arm;  // indices into the arms
};

// A closed line started at arc length s instead (its first point repeated at the end, as given).
Polyline2d rotate_closed(const Polyline2d& line, double s) {
  const Eigen::Vector2d start = sample_polyline(line, s).point;
  Polyline2d out{start};
  auto push = [&](const Eigen::Vector2d& p) {
    if ((p - out.back()).norm() > 1e-9) out.push_back(p);
  };
  std::vector<double> at{0};
  for (size_t i = 1; i < line.size(); ++i) at.push_back(at.back() + (line[i] - line[i - 1]).norm());
  for (size_t i = 1; i < line.size(); ++i)
    if (at[i] > s) push(line[i]);
  for (size_t i = 1; i < line.size(); ++i)
    if (at[i] <= s) push(line[i]);
  if ((out.back() - start).norm() > 1e-9) out.push_back(start);
  out.back() = start;
  return out;
}

// The line with a vertex at every arc length of `cuts` (sorted, inside the line; a vertex on a straight
// stretch leaves every offset line as it was) and the vertex index of each cut.
std::pair<Polyline2d, std::vector<size_t>> insert_cuts(const Polyline2d& c, const std::vector<double>& cuts) {
  // A cut this close to a vertex is at the vertex: no segment of zero length, whose normal is undefined.
  constexpr double kSameArc = 1e-6;
  Polyline2d line{c.front()};
  std::vector<size_t> at;
  double s0 = 0;
  size_t next = 0;
  for (size_t i = 1; i < c.size(); ++i) {
    const double s1 = s0 + (c[i] - c[i - 1]).norm();
    for (; next < cuts.size() && cuts[next] < s1 - kSameArc; ++next) {
      if (cuts[next] > s0 + kSameArc) line.push_back(c[i - 1] + (c[i] - c[i - 1]) * ((cuts[next] - s0) / (s1 - s0)));
      at.push_back(line.size() - 1);
    }
    line.push_back(c[i]);
    s0 = s1;
  }
  for (; next < cuts.size(); ++next) at.push_back(line.size() - 1);
  return {line, at};
}

// A bound of a connecting lanelet: a cubic Bézier from p0 leaving along h0 to p3 arriving along h3, its
// handles those of a circular arc through both ends (4/3 tan(phi/4) R, with the chord 2 R sin(phi/2)):
// a corner's quarter circle when the ends are square to each other, a straight line when aligned.
Polyline2d junction_curve(const Eigen::Vector2d& p0, const Eigen::Vector2d& h0, const Eigen::Vector2d& p3,
                          const Eigen::Vector2d& h3) {
  const double chord = (p3 - p0).norm();
  const double phi = std::abs(std::atan2(cross2(h0, h3), h0.dot(h3)));
  const double handle = phi < 1e-6 ? chord / 3 : 4.0 / 3 * std::tan(phi / 4) * chord / (2 * std::sin(phi / 2));
  const Eigen::Vector2d p1 = p0 + h0 * handle, p2 = p3 - h3 * handle;
  const int n = std::max(8, int(std::ceil((chord + 2 * handle) / kCurveStep)));
  Polyline2d out{p0};
  for (int i = 1; i < n; ++i) {
    const double t = double(i) / n, u = 1 - t;
    out.push_back(u * u * u * p0 + 3 * u * u * t * p1 + 3 * u * t * t * p2 + t * t * t * p3);
  }
  out.push_back(p3);
  return out;
}

struct StopLine {
  const RoadSpec* road;
  double s;
  RoadSide side;
  int64_t way;
};

// A stretch of a road between two cuts (the mouths of its junctions).
struct Piece {
  size_t first, last;          // vertex indices of the road's cut centreline
  double s0, s1;               // arc lengths on the centreline as given (past its length on a closed road)
  std::optional<size_t> span;  // the junction span it lies in, if any
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
          osm_.relation({way_member(left, "left"), way_member(right, "right")}, {{"type", "lanelet"},
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
      std::vector<Member> members = {relation_member(lanelet, "refers"), way_member(polygon, "crosswalk_polygon")};
      for (const bool backward : {false, true}) {
        if (backward && road.one_way) continue;
        members.push_back(way_member(stop_line_for(road, cw, backward), "ref_line"));
      }
      const int64_t regulatory = osm_.relation(members, {{"type", "regulatory_element"}, {"subtype", "crosswalk"}});
      crosswalk_elements_.push_back({&cw, regulatory});
      ++summary_.crosswalks;
    }
  }

  // The junctions of the world's roads: where centrelines cross or a road ends on another. Each road
  // through a junction is a span from mouth to mouth, the mouths where both of its edges are curbed
  // again past the corners; each side of the junction a road leaves it by is an arm.
  void junctions() {
    junctions_ = find_junctions(world_.roads);
    spans_.assign(world_.roads.size(), {});
    for (size_t j = 0; j < junctions_.size(); ++j)
      for (const JunctionRoad& jr : junctions_[j].roads) {
        const RoadSpec& road = world_.roads[jr.road];
        const double length = polyline_length(road.centreline);
        Span span{0, length, j, {}, {}};
        if (road.closed || jr.s > kArmEnd) {
          span.lo = jr.s - mouth_distance(road, carriageway_, jr.s, -1);
          span.back_arm = arms_.size();
          arms_.push_back(arm(j, jr.road, -1));
        }
        if (road.closed || jr.s < length - kArmEnd) {
          span.hi = jr.s + mouth_distance(road, carriageway_, jr.s, 1);
          span.forward_arm = arms_.size();
          arms_.push_back(arm(j, jr.road, 1));
        }
        spans_[jr.road].push_back(span);
      }
    summary_.junctions = junctions_.size();
  }

  // Autoware's road lanelets (vm-01-01): subtype=road, location=urban, one_way=yes, speed_limit in km/h.
  // Bounds are left and right of the direction of travel; Lanelet2's loader orients the two bounds by
  // geometry (lanelet2_io OsmHandlerLoad.cpp: geometry::align), so a shared divider is one way. A road
  // is cut at the mouths of its junctions. Through a junction a road that goes on keeps its lanes
  // (turn_direction=straight: Autoware vm-03-02, every lanelet in an intersection has one), bounded by
  // the road's edges where they are curbed all along and by virtual lines elsewhere; a road's end in a
  // junction has no lanelets, the connecting lanelets (junction_lanes) take its traffic on.
  void road_lanes() {
    for (size_t r = 0; r < world_.roads.size(); ++r) {
      const RoadSpec& road = world_.roads[r];
      const double length = polyline_length(road.centreline);
      std::vector<Span> spans = spans_[r];
      // A closed road starts anew in the middle of its longest stretch between junctions, so that no
      // lanelet is cut at the loop's arbitrary first point (a sliver if that lies near a junction).
      double start = 0;
      Polyline2d centre = road.centreline;
      if (road.closed && !spans.empty()) {
        for (Span& sp : spans) {
          const double shift = length * std::floor(sp.lo / length);
          sp.lo -= shift;
          sp.hi -= shift;
        }
        std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) { return a.lo < b.lo; });
        double widest = -1;
        for (size_t i = 0; i < spans.size(); ++i) {
          const double from = spans[i].hi, to = i + 1 < spans.size() ? spans[i + 1].lo : spans[0].lo + length;
          if (to - from > widest) widest = to - from, start = wrap_arc(road, (from + to) / 2);
        }
        centre = rotate_closed(road.centreline, start);
        for (Span& sp : spans) {
          sp.lo -= start;
          sp.hi -= start;
          const double shift = length * std::floor(sp.lo / length);
          sp.lo -= shift;
          sp.hi -= shift;
        }
      }
      const double centre_length = polyline_length(centre);
      std::vector<double> cuts;
      for (const Span& sp : spans)
        for (const double s : {sp.lo, sp.hi})
          if (s > 1e-6 && s < centre_length - 1e-6) cuts.push_back(s);
      // A closed road without junctions is cut half way round: a lanelet that is its own successor has no
      // start, and Lanelet2's routing graph cannot order it.
      if (road.closed && spans.empty()) cuts.push_back(centre_length / 2);
      std::sort(cuts.begin(), cuts.end());
      cuts.erase(std::unique(cuts.begin(), cuts.end(), [](double a, double b) { return b - a < 1e-6; }), cuts.end());
      const auto [line_, at] = insert_cuts(centre, cuts);
      const Polyline2d& cut_line = line_;
      std::vector<double> arc{0};
      std::vector<size_t> vertex{0};
      arc.insert(arc.end(), cuts.begin(), cuts.end());
      vertex.insert(vertex.end(), at.begin(), at.end());
      arc.push_back(centre_length);
      vertex.push_back(cut_line.size() - 1);
      auto vertex_at = [&](double s) {
        size_t best = 0;
        for (size_t k = 1; k < arc.size(); ++k)
          if (std::abs(arc[k] - s) < std::abs(arc[best] - s)) best = k;
        return vertex[best];
      };
      std::vector<Piece> pieces;
      for (size_t k = 0; k + 1 < arc.size(); ++k) {
        if (vertex[k] == vertex[k + 1]) continue;
        Piece piece{vertex[k], vertex[k + 1], arc[k] + start, arc[k + 1] + start, {}};
        const double mid = (arc[k] + arc[k + 1]) / 2;
        for (size_t i = 0; i < spans.size(); ++i)
          if (spans[i].lo <= mid && mid <= spans[i].hi) piece.span = i;
        pieces.push_back(piece);
      }

      const double lane_width = road.width / road.lanes;
      std::vector<Polyline2d> offsets;
      for (int k = 0; k <= road.lanes; ++k)
        offsets.push_back(offset_polyline(cut_line, -road.width / 2 + k * lane_width, road.closed));
      for (const Span& sp : spans)
        for (const auto& [arm, s] : {std::pair{sp.back_arm, sp.lo}, std::pair{sp.forward_arm, sp.hi}}) {
          if (!arm) continue;
          for (const Polyline2d& o : offsets) arms_[*arm].points.push_back(o[vertex_at(s)]);
          arms_[*arm].tangent = sample_polyline(cut_line, s).tangent;
        }

      for (const Piece& p : pieces) {
        const bool in_junction = p.span.has_value();
        if (in_junction && !(spans[*p.span].back_arm && spans[*p.span].forward_arm)) continue;  // the road ends here
        if (!in_junction && p.s1 - p.s0 < kMinLanelet) ++summary_.short_lanelets;
        // bounds[k]: the line k lanes from the right curb over the piece.
        std::vector<int64_t> bounds;
        for (int k = 0; k <= road.lanes; ++k) {
          const bool edge = k == 0 || k == road.lanes;
          Tags tags = edge ? border_tags() : divider_tags(road.marking);
          if (in_junction && (!edge || edge_opens(road, p, k == 0 ? -1 : 1))) tags = junction_line_tags();
          const Polyline2d& o = offsets[size_t(k)];
          bounds.push_back(line(Polyline2d(o.begin() + long(p.first), o.begin() + long(p.last) + 1), tags));
        }
        for (int j = 0; j < road.lanes; ++j) {
          const int travel = lane_travel(road, j);
          const int64_t right_line = bounds[size_t(travel < 0 ? j + 1 : j)];
          const int64_t left_line = bounds[size_t(travel < 0 ? j : j + 1)];
          std::vector<Member> members = {way_member(left_line, "left"), way_member(right_line, "right")};
          for (const auto& [cw, regulatory] : crosswalk_elements_)
            if (cw->road == road.name && crosses(road, p, *cw))
              members.push_back(relation_member(regulatory, "regulatory_element"));
          Tags tags = lane_tags(travel != 0, road.design_speed);
          if (in_junction) {
            tags.emplace_back("turn_direction", "straight");
            ++summary_.intersection_lanelets;
          }
          osm_.relation(members, tags);
          ++summary_.road_lanelets;
        }
      }
    }
  }

  // Lanelets through every junction for each movement the roads allow: from the end of each lane
  // arriving at the junction by one road to the start of each lane leaving it by another (a road that
  // goes on has its own straight lanelets, road_lanes; no U-turns), so every lane reaches every other
  // where the roads allow (lanelet2_routing finds successors by shared end points, geometry::follows).
  // Bounds are virtual curves (nothing is painted in the junction), turn_direction straight, left or
  // right as Autoware's intersection and blinker modules read it (vm-03-02).
  void junction_lanes() {
    for (size_t a = 0; a < arms_.size(); ++a)
      for (size_t b = 0; b < arms_.size(); ++b) {
        const Arm &in = arms_[a], &out = arms_[b];
        if (in.junction != out.junction || in.road == out.road) continue;
        const RoadSpec &from = world_.roads[in.road], &to = world_.roads[out.road];
        const Eigen::Vector2d h_in = -in.dir * in.tangent, h_out = out.dir * out.tangent;
        const double turn = std::atan2(cross2(h_in, h_out), h_in.dot(h_out));
        if (std::abs(turn) > kMaxTurn) continue;
        const char* direction = std::abs(turn) <= kStraightWithin ? "straight" : turn > 0 ? "left" : "right";
        for (int ja = 0; ja < from.lanes; ++ja) {
          const int ta = lane_travel(from, ja);
          if (ta != -in.dir && ta != 0) continue;  // leaves the junction
          const bool along_in = in.dir < 0;        // travels along the centreline towards the junction
          const Eigen::Vector2d left_in = in.points[size_t(along_in ? ja + 1 : ja)];
          const Eigen::Vector2d right_in = in.points[size_t(along_in ? ja : ja + 1)];
          for (int jb = 0; jb < to.lanes; ++jb) {
            const int tb = lane_travel(to, jb);
            if (tb != out.dir && tb != 0) continue;  // arrives at the junction
            const bool along_out = out.dir > 0;
            const Eigen::Vector2d left_out = out.points[size_t(along_out ? jb + 1 : jb)];
            const Eigen::Vector2d right_out = out.points[size_t(along_out ? jb : jb + 1)];
            const int64_t left = line(junction_curve(left_in, h_in, left_out, h_out), junction_line_tags());
            const int64_t right = line(junction_curve(right_in, h_in, right_out, h_out), junction_line_tags());
            Tags tags = lane_tags(true, std::min(from.design_speed, to.design_speed));
            tags.emplace_back("turn_direction", direction);
            osm_.relation({way_member(left, "left"), way_member(right, "right")}, tags);
            ++summary_.road_lanelets;
            ++summary_.intersection_lanelets;
            ++summary_.turn_lanelets;
          }
        }
      }
  }

  Lanelet2Summary write(const std::string& path, const std::string& map_version) {
    osm_.write(path, map_version);
    summary_.nodes = osm_.nodes();
    return summary_;
  }

 private:
  static Tags stop_line_tags() { return {{"type", "stop_line"}}; }

  // The speed limit is the road's design speed (RoadSpec::design_speed, km/h: Autoware's speed_limit
  // tag is in km/h, vm-01-01).
  static Tags lane_tags(bool one_way, double speed_kmh) {
    return {{"type", "lanelet"},
            {"subtype", "road"},
            {"location", "urban"},
            {"one_way", one_way ? "yes" : "no"},
            {"speed_limit", shortest_decimal(speed_kmh)},
            {"participant:vehicle", "yes"}};
  }

  // Whether the road's edge on `side` (-1 right, 1 left) opens into another carriageway anywhere along
  // the piece.
  bool edge_opens(const RoadSpec& road, const Piece& p, int side) const {
    for (double s = p.s0; s <= p.s1; s += kMouthStep)
      if (edge_open(road, carriageway_, s, side)) return true;
    return false;
  }

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
  std::vector<Junction> junctions_;
  std::vector<std::vector<Span>> spans_;  // per road
  std::vector<Arm> arms_;
};

}  // namespace

const char* curbstone_subtype(const std::string& kind) {
  // Lanelet2 LinestringTagging.md: `high` is too high for a vehicle to drive over, `low` can be driven
  // over. A vertical (barrier) curb is high; sloped and rolled curbs are mountable (AASHTO 4.7) and a cut
  // is level with the road, so they are low.
  return kind == curb_profile_name(CurbProfile::vertical) ? "high" : "low";
}

Lanelet2Summary write_lanelet2_map(const std::string& path, const WorldDescription& world, const World& built,
                                   const CurbMap& curbs, const SurveyedLine& surveyed, const std::string& map_version) {
  MapBuilder builder(world, built, surveyed);
  builder.curbs(curbs);
  builder.stop_lines();
  builder.crosswalks();  // before the lanes, which list the crosswalks' regulatory elements
  builder.junctions();
  builder.road_lanes();  // before the junction lanes, which start and end at the lanes' mouths
  builder.junction_lanes();
  return builder.write(path, map_version);
}

}  // namespace lidarloop
