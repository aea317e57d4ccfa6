#include "sim/world_description.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "common/input_error.hpp"
#include "common/path_beside.hpp"
#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "sim/actor_assets.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kMaxArcStep = 3.0 * kDeg;  // fillet arcs are split every 3 degrees
constexpr double kMinSegment = 0.01;        // m; shorter centreline segments are input errors
// m between a construction zone's temporary kerb and a quarter of the road width (where its barriers
// stand): a barrier's half width (0.305 m) and a kerb block's (0.15 m), rounded up.
constexpr double kKerbClearance = 0.5;
constexpr double kMaxTurn = 170.0 * kDeg;  // sharper turns between segments are a road doubling back

MarkingStyle read_marking(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "marking");
  if (s == "none") return MarkingStyle::none;
  if (s == "solid") return MarkingStyle::solid;
  if (s == "dashed") return MarkingStyle::dashed;
  y.fail(n, "marking must be solid, dashed or none, got '" + s + "'");
}

}  // namespace

RoadSide read_side(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "side");
  if (s == "left") return RoadSide::left;
  if (s == "right") return RoadSide::right;
  if (s == "both") return RoadSide::both;
  y.fail(n, "side must be left, right or both, got '" + s + "'");
}

namespace {

CurbProfile read_curb_profile(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "curb_profile");
  if (s == "vertical") return CurbProfile::vertical;
  if (s == "sloped") return CurbProfile::sloped;
  if (s == "rolled") return CurbProfile::rolled;
  y.fail(n, "curb_profile must be vertical, sloped or rolled, got '" + s + "'");
}

CurbCut read_cut_kind(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "kind");
  if (s == "driveway") return CurbCut::driveway;
  if (s == "ramp") return CurbCut::ramp;
  if (s == "flush") return CurbCut::flush;
  y.fail(n, "kind must be driveway, ramp or flush, got '" + s + "'");
}

// Road properties that may appear both in road_defaults and on each road.
void read_road_properties(YamlMap& m, RoadSpec& road) {
  const YamlReader& y = m.reader();
  m.number("width", road.width, 2.5, 40.0)
      .integer("lanes", road.lanes, 1, 8)
      .boolean("one_way", road.one_way)
      .boolean("edge_lines", road.edge_lines)
      .number("curb_height", road.curb_height, 0.05, 0.30)
      .number("sidewalk_width", road.sidewalk_width, 0.0, 15.0)
      .number("smoothing_radius", road.smoothing_radius, 0.0, 500.0)
      .number("cross_slope", road.cross_slope, 0.0, 0.08)
      .number("design_speed", road.design_speed, 5.0, 130.0)
      .number("curb_height_variation", road.curb_height_variation, 0.0, 0.1)
      .number("gutter_width", road.gutter_width, 0.0, 1.8)
      .number("gutter_slope", road.gutter_slope, 0.0, 0.12)
      .number("driveway_spacing", road.driveway_spacing, 0.0, 1000.0)
      .number("driveway_width", road.driveway_width, 2.0, 15.0)
      .number("verge_width", road.verge_width, 0.0, 10.0);
  if (const YAML::Node marking = m["marking"]) road.marking = read_marking(y, marking);
  if (const YAML::Node profile = m["curb_profile"]) road.curb_profile = read_curb_profile(y, profile);
  if (road.curb_height_variation >= road.curb_height)
    y.fail(m["curb_height_variation"] ? m["curb_height_variation"] : m.node(),
           "curb_height_variation must be below curb_height");
  if (road.driveway_spacing > 0 && road.driveway_spacing <= road.driveway_width)
    y.fail(m["driveway_spacing"], "driveway_spacing must exceed driveway_width");
}

RoadSpec read_road(const YamlReader& y, const YAML::Node& n, const RoadSpec& defaults) {
  YamlMap m(y, n, "a road");
  RoadSpec road = defaults;
  road.where = m.where();
  road.name = y.string(m.required("name"), "road name");
  read_road_properties(m, road);
  m.boolean("closed", road.closed);
  const YAML::Node points = m.required("points");
  m.done();
  y.expect_sequence(points, "points");
  for (const auto& p : points) road.points.push_back(y.vec2(p, "a road point"));
  if (road.points.size() < (road.closed ? 3u : 2u))
    y.fail(points, "road '" + road.name + "' needs at least " + (road.closed ? "3" : "2") + " points");
  if (road.closed) road.points.push_back(road.points.front());
  for (size_t i = 1; i < road.points.size(); ++i)
    if ((road.points[i] - road.points[i - 1]).norm() < kMinSegment)
      y.fail(points[i % points.size()], "road '" + road.name + "' has a zero-length segment between points " +
                                            std::to_string(i - 1) + " and " + std::to_string(i % points.size()));
  if (auto hit = find_self_intersection(road.points, road.closed))
    y.fail(points, "road '" + road.name + "' intersects itself (segments " + std::to_string(hit->first) + " and " +
                       std::to_string(hit->second) + ")");
  for (size_t i = 1; i + 1 < road.points.size(); ++i) {
    const Eigen::Vector2d a = road.points[i] - road.points[i - 1], b = road.points[i + 1] - road.points[i];
    if (a.dot(b) < std::cos(kMaxTurn) * a.norm() * b.norm())
      y.fail(points[i], "road '" + road.name + "' turns back on itself at point " + std::to_string(i));
  }
  // fillet_polyline takes a closed line without its repeated first point.
  Polyline2d corners = road.points;
  if (road.closed) corners.pop_back();
  road.centreline = fillet_polyline(corners, road.smoothing_radius, road.closed, kMaxArcStep);
  return road;
}

void read_row(YamlMap& m, RowSpec& row) {
  row.where = m.where();
  row.road = m.reader().string(m.required("road"), "road");
  if (const YAML::Node side = m["side"]) row.side = read_side(m.reader(), side);
  m.number("spacing", row.spacing, 2.0, 1000.0)
      .number("setback", row.setback, 0.0, 50.0)
      .number("start", row.start, 0.0, 1e5);
}

// A position along a road: `at` (arc length along its centreline) or `near: [x, y]` (projected onto it).
double read_station(YamlMap& m, const WorldDescription& w, const std::string& road) {
  const YamlReader& y = m.reader();
  const YAML::Node at = m["at"], near = m["near"];
  if (at && near) y.fail(m.node(), "give either 'at' or 'near', not both");
  if (at) return y.number_in(at, "at", 0.0, 1e5);
  if (!near) y.fail(m.node(), "missing key 'at' (arc length along the road) or 'near' ([x, y])");
  const RoadSpec* r = w.road(road);
  if (!r) y.fail(m.node()["road"], "unknown road '" + road + "'");
  return project_onto_polyline(r->centreline, y.vec2(near, "near"));
}

// Each entry of root[key] is a mapping, read by `read` and then checked for keys it did not read.
template <class Item, class Read>
void read_list(YamlMap& root, const char* key, std::vector<Item>& out, Read read) {
  const YAML::Node list = root[key];
  if (!list) return;
  root.reader().expect_sequence(list, key);
  for (const auto& n : list) {
    YamlMap m(root.reader(), n, std::string("an entry of ") + key);
    out.push_back(read(m));
    m.done();
  }
}

// Names used by crosswalks, stop lines and rows must be roads, and arc lengths must be on them.
void check_references(const YamlReader& y, const YAML::Node& root, WorldDescription& w) {
  auto check = [&](const char* key, size_t i, const std::string& road, double at, bool has_at) {
    const RoadSpec* r = w.road(road);
    const YAML::Node entry = root[key][i];
    if (!r) y.fail(entry["road"], std::string(key) + " refers to unknown road '" + road + "'");
    if (has_at && at > polyline_length(r->centreline))
      y.fail(entry["at"] ? entry["at"] : entry, "at = " + std::to_string(at) + " m is beyond the end of road '" + road +
                                                    "' (" + std::to_string(polyline_length(r->centreline)) + " m)");
  };
  for (size_t i = 0; i < w.crosswalks.size(); ++i)
    check("crosswalks", i, w.crosswalks[i].road, w.crosswalks[i].at, true);
  for (size_t i = 0; i < w.stop_lines.size(); ++i)
    check("stop_lines", i, w.stop_lines[i].road, w.stop_lines[i].at, true);
  for (size_t i = 0; i < w.curb_cuts.size(); ++i) check("curb_cuts", i, w.curb_cuts[i].road, w.curb_cuts[i].at, true);
  for (size_t i = 0; i < w.poles.size(); ++i) check("poles", i, w.poles[i].road, 0, false);
  for (size_t i = 0; i < w.trees.size(); ++i) check("trees", i, w.trees[i].road, 0, false);
  for (size_t i = 0; i < w.bollards.size(); ++i) check("bollards", i, w.bollards[i].road, 0, false);
  for (size_t i = 0; i < w.hydrants.size(); ++i) check("hydrants", i, w.hydrants[i].road, 0, false);
  for (size_t i = 0; i < w.hedges.size(); ++i) check("hedges", i, w.hedges[i].road, w.hedges[i].at, true);
}

ParkedVehicleSpec read_parked(YamlMap& m) {
  const YamlReader& y = m.reader();
  ParkedVehicleSpec p;
  p.where = m.where();
  if (const YAML::Node type = m["type"]) {
    p.type = y.string(type, "type");
    if (!actor_type_from_name(p.type))
      y.fail(type, "unknown vehicle type '" + p.type + "' (expected one of: " + actor_type_names() + ")");
  }
  p.position = y.vec2(m.required("position"), "position");
  m.degrees("yaw_deg", p.yaw, -360.0, 360.0);
  return p;
}

HedgeSpec read_hedge(YamlMap& m, const WorldDescription& w) {
  const YamlReader& y = m.reader();
  HedgeSpec h;
  h.where = m.where();
  h.road = y.string(m.required("road"), "road");
  h.at = read_station(m, w, h.road);
  if (const YAML::Node side = m["side"]) h.side = read_side(y, side);
  m.number("length", h.length, 1.0, 5000.0)
      .number("setback", h.setback, 0.0, 20.0)
      .number("depth", h.depth, 0.2, 5.0)
      .number("height", h.height, 0.3, 5.0)
      .number("overhang", h.overhang, 0.0, 2.0)
      .number("clearance", h.clearance, 0.0, 3.0);
  if (h.clearance >= h.height) y.fail(m.node(), "a hedge's clearance must be below its height");
  return h;
}

// world.yaml's `lanelet2` section: the map (a path relative to the world file) and what the map leaves
// unsaid (sim/lanelet2_world.hpp's Lanelet2WorldParams).
std::shared_ptr<const Lanelet2Source> read_lanelet2_source(const YamlReader& y, const YAML::Node& n,
                                                           const std::optional<Geodetic>& origin,
                                                           const WorldGeometryParams& geometry) {
  YamlMap m(y, n, "lanelet2");
  const YAML::Node file = m.required("file");
  Lanelet2WorldParams p;
  p.geometry = geometry;
  m.string("country", p.country)
      .number("parking_occupancy", p.parking_occupancy, 0.0, 1.0)
      .integer("seed", p.seed, 0, uint64_t(1) << 62)
      .number("curb_high", p.curb_high, 0.0, 0.5)
      .number("curb_low", p.curb_low, 0.0, 0.3)
      .number("cross_slope", p.cross_slope, 0.0, 0.1);
  m.done();
  Lanelet2ReadOptions read;
  read.origin = origin;
  try {
    return load_lanelet2_source(path_beside(y.file(), y.string(file, "file")), m.where(), p, read);
  } catch (const InputError& e) {
    y.fail(file, e.what());
  }
}

// world.yaml's `opendrive` section: the map (a path relative to the world file) and what the map leaves
// unsaid (sim/opendrive_world.hpp's OdrWorldParams). The world's `origin` is the map's x / y origin
// where the map's geoReference is a placeholder.
std::shared_ptr<const OpenDriveSource> read_opendrive_source(const YamlReader& y, const YAML::Node& n,
                                                             const std::optional<Geodetic>& origin,
                                                             const WorldGeometryParams& geometry) {
  YamlMap m(y, n, "opendrive");
  const YAML::Node file = m.required("file");
  OdrWorldParams p;
  p.geometry = geometry;
  m.number("parking_occupancy", p.parking_occupancy, 0.0, 1.0)
      .integer("seed", p.seed, 0, uint64_t(1) << 62)
      .number("sidewalk_height", p.sidewalk_height, 0.0, 0.5)
      .number("curb_threshold", p.curb_threshold, 0.005, 0.2)
      .boolean("paint_junctions", p.paint_junctions);
  m.done();
  OdrReadOptions read;
  read.origin = origin;
  try {
    return load_opendrive_source(path_beside(y.file(), y.string(file, "file")), m.where(), p, read);
  } catch (const InputError& e) {
    y.fail(file, e.what());
  }
}

WorldDescription parse(const YamlReader& y) {
  YamlMap root(y, y.root(), "a world description");
  WorldDescription w;
  w.file = y.file();
  w.name = y.string(root.required("name"), "name");

  // A Lanelet2 map brings its own road network and, unless `origin` says otherwise, its own origin.
  const YAML::Node lanelet2 = root["lanelet2"], opendrive = root["opendrive"];
  const YAML::Node origin_node = lanelet2 || opendrive ? root["origin"] : root.required("origin");
  if (origin_node) {
    YamlMap origin(y, origin_node, "origin");
    w.origin.lat_deg = y.number_in(origin.required("lat"), "lat", -85.0, 85.0);
    w.origin.lon_deg = y.number_in(origin.required("lon"), "lon", -180.0, 180.0);
    origin.number("alt", w.origin.alt_m, -500.0, 9000.0).done();
  }

  auto& g = w.geometry;
  YamlMap geometry(y, root["geometry"], "geometry");
  geometry.number("corner_radius", g.corner_radius, 0.0, 50.0)
      .number("curb_top_width", g.curb_top_width, 0.05, 0.5)
      .number("paint_width", g.paint_width, 0.05, 1.0)
      .number("paint_height", g.paint_height, 0.001, 0.02)
      .number("dash_length", g.dash_length, 0.5, 20.0)
      .number("dash_gap", g.dash_gap, 0.5, 30.0)
      .number("edge_line_inset", g.edge_line_inset, 0.1, 2.0)
      .number("stop_line_width", g.stop_line_width, 0.1, 1.0)
      .number("crosswalk_stripe", g.crosswalk_stripe, 0.2, 1.0)
      .number("crosswalk_gap", g.crosswalk_gap, 0.2, 2.0)
      .number("margin", g.margin, 0.0, 500.0)
      .number("sidewalk_cross_slope", g.sidewalk_cross_slope, 0.0, 0.1)
      .number("ramp_slope", g.ramp_slope, 0.01, 0.5)
      .number("flare_slope", g.flare_slope, 0.01, 0.5)
      .number("max_superelevation", g.max_superelevation, 0.0, 0.12)
      .number("roughness_min_wavelength", g.roughness_min_wavelength, 0.1, 100.0)
      .number("roughness_max_wavelength", g.roughness_max_wavelength, 0.1, 1000.0)
      .integer("roughness_seed", g.roughness_seed, 0, uint64_t(1) << 62)
      .boolean("crosswalk_ramps", g.crosswalk_ramps);
  if (const YAML::Node c = geometry["roughness_class"]) {
    const std::string s = y.string(c, "roughness_class");
    if (s != "none" && (s.size() != 1 || s[0] < 'A' || s[0] > 'E'))
      y.fail(c, "roughness_class must be an ISO 8608 class A-E or none, got '" + s + "'");
    g.roughness_class = s == "none" ? '-' : s[0];
  }
  if (g.roughness_min_wavelength >= g.roughness_max_wavelength)
    y.fail(geometry.node(), "roughness_min_wavelength must be below roughness_max_wavelength");
  geometry.done();

  RoadSpec defaults;
  YamlMap road_defaults(y, root["road_defaults"], "road_defaults");
  read_road_properties(road_defaults, defaults);
  road_defaults.done();
  if (lanelet2 && opendrive) y.fail(opendrive, "a world has either a lanelet2 or an opendrive map, not both");
  if (opendrive) {
    if (root["roads"]) y.fail(root["roads"], "a world has either roads or an opendrive map, not both");
    for (const char* key :
         {"road_defaults", "crosswalks", "stop_lines", "curb_cuts", "poles", "trees", "bollards", "hydrants", "hedges"})
      if (root[key])
        y.fail(root[key],
               std::string(key) + " are placed along roads; a world from an opendrive map takes them from the map");
    w.opendrive =
        read_opendrive_source(y, opendrive, origin_node ? std::optional<Geodetic>(w.origin) : std::nullopt, w.geometry);
    w.origin = w.opendrive->map.origin;
  }
  if (lanelet2) {
    if (root["roads"]) y.fail(root["roads"], "a world has either roads or a lanelet2 map, not both");
    for (const char* key :
         {"road_defaults", "crosswalks", "stop_lines", "curb_cuts", "poles", "trees", "bollards", "hydrants", "hedges"})
      if (root[key])
        y.fail(root[key],
               std::string(key) + " are placed along roads; a world from a lanelet2 map takes them from the map");
    w.lanelet2 =
        read_lanelet2_source(y, lanelet2, origin_node ? std::optional<Geodetic>(w.origin) : std::nullopt, w.geometry);
    w.origin = w.lanelet2->map.origin;
  }
  const YAML::Node roads = lanelet2 || opendrive ? YAML::Node(YAML::NodeType::Sequence) : root.required("roads");
  y.expect_sequence(roads, "roads");
  if (roads.size() == 0 && !lanelet2 && !opendrive) y.fail(roads, "a world needs at least one road");
  for (const auto& n : roads) {
    RoadSpec road = read_road(y, n, defaults);
    if (w.road(road.name)) y.fail(n["name"], "road name '" + road.name + "' is used twice");
    w.roads.push_back(std::move(road));
  }

  read_list(root, "crosswalks", w.crosswalks, [&](YamlMap& m) {
    CrosswalkSpec c;
    c.where = m.where();
    c.road = y.string(m.required("road"), "road");
    c.at = read_station(m, w, c.road);
    m.number("width", c.width, 1.0, 20.0);
    return c;
  });
  read_list(root, "stop_lines", w.stop_lines, [&](YamlMap& m) {
    StopLineSpec s;
    s.where = m.where();
    s.road = y.string(m.required("road"), "road");
    s.at = read_station(m, w, s.road);
    if (const YAML::Node side = m["side"]) s.side = read_side(y, side);
    return s;
  });
  read_list(root, "curb_cuts", w.curb_cuts, [&](YamlMap& m) {
    CurbCutSpec c;
    c.where = m.where();
    c.road = y.string(m.required("road"), "road");
    c.at = read_station(m, w, c.road);
    if (const YAML::Node side = m["side"]) c.side = read_side(y, side);
    if (c.side == RoadSide::both) y.fail(m["side"], "a curb cut is on one side: left or right");
    m.number("length", c.length, 1.0, 500.0);
    if (const YAML::Node kind = m["kind"]) c.kind = read_cut_kind(y, kind);
    return c;
  });
  read_list(root, "hills", w.hills, [&](YamlMap& m) {
    Hill h;
    h.centre = y.vec2(m.required("centre"), "centre");
    h.radius = y.number_in(m.required("radius"), "radius", 10.0, 1e5);
    h.height = y.number_in(m.required("height"), "height", -200.0, 200.0);
    return h;
  });
  read_list(root, "buildings", w.buildings, [&](YamlMap& m) {
    BuildingSpec b;
    b.where = m.where();
    b.centre = y.vec2(m.required("centre"), "centre");
    const YAML::Node size = m.required("size");
    b.size = y.vec2(size, "size");
    if (b.size.minCoeff() < 1.0) y.fail(size, "building size must be at least 1 m each way");
    m.degrees("yaw_deg", b.yaw, -360.0, 360.0).number("height", b.height, 2.0, 300.0).string("material", b.material);
    return b;
  });
  read_list(root, "poles", w.poles, [&](YamlMap& m) {
    PoleRow p;
    read_row(m, p);
    m.number("height", p.height, 1.0, 20.0).boolean("sign", p.sign);
    return p;
  });
  read_list(root, "trees", w.trees, [&](YamlMap& m) {
    TreeRow t;
    read_row(m, t);
    m.number("height", t.height, 2.0, 40.0).number("crown_radius", t.crown_radius, 0.5, 10.0);
    return t;
  });
  read_list(root, "bollards", w.bollards, [&](YamlMap& m) {
    BollardRow b;
    b.setback = 0.45;
    read_row(m, b);
    m.number("height", b.height, 0.3, 2.0).number("diameter", b.diameter, 0.05, 0.6);
    return b;
  });
  read_list(root, "hydrants", w.hydrants, [&](YamlMap& m) {
    HydrantRow h;
    // Hydrants stand 300-500 ft (90-150 m) apart along a street, about 2 ft behind the curb face
    // (common municipal practice, an assumption: no one standard fixes either).
    h.setback = 0.6;
    h.spacing = 120;
    read_row(m, h);
    m.number("height", h.height, 0.3, 1.5).number("diameter", h.diameter, 0.1, 0.6);
    return h;
  });
  read_list(root, "hedges", w.hedges, [&](YamlMap& m) { return read_hedge(m, w); });
  read_list(root, "parked_vehicles", w.parked, [&](YamlMap& m) { return read_parked(m); });
  root.done();
  check_references(y, y.root(), w);
  return w;
}

}  // namespace

const RoadSpec* WorldDescription::road(const std::string& name) const {
  for (const auto& r : roads)
    if (r.name == name) return &r;
  return nullptr;
}

WorldDescription apply_world_changes(WorldDescription w, const YamlReader& y, const YAML::Node& changes) {
  YamlMap root(y, changes, "world_changes");
  if (const YAML::Node gone = root["parked_vehicles_gone"]) {
    y.expect_sequence(gone, "parked_vehicles_gone");
    constexpr double kMatch = 1.0;  // m between a listed position and the parked vehicle's
    for (const auto& n : gone) {
      const Eigen::Vector2d at = y.vec2(n, "parked_vehicles_gone");
      const auto it = std::find_if(w.parked.begin(), w.parked.end(),
                                   [&](const ParkedVehicleSpec& p) { return (p.position - at).norm() < kMatch; });
      if (it == w.parked.end()) y.fail(n, "no parked vehicle of world '" + w.name + "' within 1 m of this position");
      w.parked.erase(it);
    }
  }
  read_list(root, "parked_vehicles_new", w.parked, [&](YamlMap& m) { return read_parked(m); });
  auto stretch = [&](YamlMap& m, std::string& where, std::string& road, double& at, double& length) {
    where = m.where();
    road = y.string(m.required("road"), "road");
    at = read_station(m, w, road);
    m.number("length", length, 1.0, 5000.0);
    const RoadSpec* r = w.road(road);
    if (!r) y.fail(m.node()["road"], "unknown road '" + road + "'");
    if (at > polyline_length(r->centreline)) y.fail(m.node(), "beyond the end of road '" + road + "'");
  };
  // Seasonal vegetation: hedges grown (or planted) since the survey.
  read_list(root, "vegetation_grown", w.hedges, [&](YamlMap& m) {
    HedgeSpec h = read_hedge(m, w);
    const RoadSpec* r = w.road(h.road);
    if (!r) y.fail(m.node()["road"], "unknown road '" + h.road + "'");
    return h;
  });
  read_list(root, "paint_worn", w.paint_changes, [&](YamlMap& m) {
    PaintChange c;
    stretch(m, c.where, c.road, c.at, c.length);
    return c;
  });
  read_list(root, "paint_repainted", w.paint_changes, [&](YamlMap& m) {
    PaintChange c;
    stretch(m, c.where, c.road, c.at, c.length);
    c.shift = y.number_in(m.required("shift"), "shift", -5.0, 5.0);
    return c;
  });
  read_list(root, "construction", w.construction, [&](YamlMap& m) {
    ConstructionZone z;
    stretch(m, z.where, z.road, z.at, z.length);
    if (const YAML::Node side = m["side"]) z.side = read_side(y, side);
    if (z.side == RoadSide::both) y.fail(m["side"], "a construction zone closes one side: left or right");
    m.boolean("curb_removed", z.curb_removed);
    // The temporary kerb stays on the closed lanes' outer half, clear of the barriers down their middle.
    const double max_shift = w.road(z.road)->width / 4 - kKerbClearance;
    if (const YAML::Node shift = m["curb_shift"]) z.curb_shift = y.number_in(shift, "curb_shift", 0.0, max_shift);
    if (z.curb_removed)  // no curb at all over the zone: a flush cut (CurbCut::flush)
      w.curb_cuts.push_back({z.where, z.road, z.side, z.at, z.length, CurbCut::flush});
    return z;
  });
  root.done();
  return w;
}

WorldDescription on_ideal_ground(WorldDescription d) {
  d.geometry.sidewalk_cross_slope = 0;
  d.geometry.roughness_class = '-';
  d.geometry.crosswalk_ramps = false;
  d.geometry.max_superelevation = 0;
  d.hills.clear();
  d.curb_cuts.clear();
  for (RoadSpec& r : d.roads) {
    r.cross_slope = 0;
    r.curb_profile = CurbProfile::vertical;
    r.curb_height_variation = 0;
    r.gutter_width = 0;
    r.driveway_spacing = 0;
  }
  return d;
}

WorldDescription load_world_description(const std::string& path) { return parse(YamlReader::open(path)); }

WorldDescription lanelet2_world_description(const std::string& osm_path) {
  WorldDescription w;
  w.name = std::filesystem::path(osm_path).stem().string();
  w.file = osm_path;
  w.lanelet2 = load_lanelet2_source(osm_path, osm_path, {});
  w.origin = w.lanelet2->map.origin;
  return w;
}

WorldDescription opendrive_world_description(const std::string& xodr_path) {
  WorldDescription w;
  w.name = std::filesystem::path(xodr_path).stem().string();
  w.file = xodr_path;
  w.opendrive = load_opendrive_source(xodr_path, xodr_path, {});
  w.origin = w.opendrive->map.origin;
  return w;
}

WorldDescription parse_world_description(const std::string& yaml_text, const std::string& name) {
  return parse(YamlReader::from_string(yaml_text, name));
}

}  // namespace lidarloop
