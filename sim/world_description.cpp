#include "sim/world_description.hpp"

#include <cmath>

#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "sim/actor_assets.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kMaxArcStep = 3.0 * kDeg;  // fillet arcs are split every 3 degrees
constexpr double kMinSegment = 0.01;        // m; shorter centreline segments are input errors
constexpr double kMaxTurn = 170.0 * kDeg;   // sharper turns between segments are a road doubling back

MarkingStyle read_marking(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "marking");
  if (s == "none") return MarkingStyle::none;
  if (s == "solid") return MarkingStyle::solid;
  if (s == "dashed") return MarkingStyle::dashed;
  y.fail(n, "marking must be solid, dashed or none, got '" + s + "'");
}

RoadSide read_side(const YamlReader& y, const YAML::Node& n) {
  const std::string s = y.string(n, "side");
  if (s == "left") return RoadSide::left;
  if (s == "right") return RoadSide::right;
  if (s == "both") return RoadSide::both;
  y.fail(n, "side must be left, right or both, got '" + s + "'");
}

// Road properties that may appear both in road_defaults and on each road.
void read_road_properties(const YamlReader& y, const YAML::Node& n, RoadSpec& road) {
  if (n["width"]) road.width = y.number_in(n["width"], "width", 2.5, 40.0);
  if (n["lanes"]) road.lanes = static_cast<int>(y.integer_in(n["lanes"], "lanes", 1, 8));
  if (n["one_way"]) road.one_way = y.boolean(n["one_way"], "one_way");
  if (n["marking"]) road.marking = read_marking(y, n["marking"]);
  if (n["edge_lines"]) road.edge_lines = y.boolean(n["edge_lines"], "edge_lines");
  if (n["curb_height"]) road.curb_height = y.number_in(n["curb_height"], "curb_height", 0.05, 0.30);
  if (n["sidewalk_width"]) road.sidewalk_width = y.number_in(n["sidewalk_width"], "sidewalk_width", 0.0, 15.0);
  if (n["smoothing_radius"]) road.smoothing_radius = y.number_in(n["smoothing_radius"], "smoothing_radius", 0.0, 500.0);
}
#define ROAD_PROPERTY_KEYS \
  "width", "lanes", "one_way", "marking", "edge_lines", "curb_height", "sidewalk_width", "smoothing_radius"

RoadSpec read_road(const YamlReader& y, const YAML::Node& n, const RoadSpec& defaults) {
  y.expect_map(n, "a road");
  y.allow_keys(n, {"name", "points", "closed", ROAD_PROPERTY_KEYS});
  RoadSpec road = defaults;
  road.where = yaml_location(y.file(), n);
  road.name = y.string(y.required(n, "name"), "road name");
  read_road_properties(y, n, road);
  if (n["closed"]) road.closed = y.boolean(n["closed"], "closed");
  const YAML::Node points = y.required(n, "points");
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

void read_row(const YamlReader& y, const YAML::Node& n, RowSpec& row) {
  row.where = yaml_location(y.file(), n);
  row.road = y.string(y.required(n, "road"), "road");
  if (n["side"]) row.side = read_side(y, n["side"]);
  if (n["spacing"]) row.spacing = y.number_in(n["spacing"], "spacing", 2.0, 1000.0);
  if (n["setback"]) row.setback = y.number_in(n["setback"], "setback", 0.0, 50.0);
  if (n["start"]) row.start = y.number_in(n["start"], "start", 0.0, 1e5);
}

// A position along a road: `at` (arc length along its centreline) or `near: [x, y]` (projected onto it).
double read_station(const YamlReader& y, const YAML::Node& n, const WorldDescription& w, const std::string& road) {
  if (n["at"] && n["near"]) y.fail(n, "give either 'at' or 'near', not both");
  if (n["at"]) return y.number_in(n["at"], "at", 0.0, 1e5);
  if (!n["near"]) y.fail(n, "missing key 'at' (arc length along the road) or 'near' ([x, y])");
  const RoadSpec* r = w.road(road);
  if (!r) y.fail(n["road"], "unknown road '" + road + "'");
  return project_onto_polyline(r->centreline, y.vec2(n["near"], "near"));
}

template <class Item, class Read>
void read_list(const YamlReader& y, const YAML::Node& root, const char* key, std::vector<Item>& out, Read read) {
  const YAML::Node list = root[key];
  if (!list) return;
  y.expect_sequence(list, key);
  for (const auto& n : list) {
    y.expect_map(n, std::string("an entry of ") + key);
    out.push_back(read(n));
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
  for (size_t i = 0; i < w.poles.size(); ++i) check("poles", i, w.poles[i].road, 0, false);
  for (size_t i = 0; i < w.trees.size(); ++i) check("trees", i, w.trees[i].road, 0, false);
}

WorldDescription parse(const YamlReader& y) {
  const YAML::Node& root = y.root();
  y.expect_map(root, "a world description");
  y.allow_keys(root, {"name", "origin", "road_defaults", "geometry", "roads", "crosswalks", "stop_lines", "buildings",
                      "poles", "trees", "parked_vehicles"});
  WorldDescription w;
  w.file = y.file();
  w.name = y.string(y.required(root, "name"), "name");

  const YAML::Node origin = y.required(root, "origin");
  y.expect_map(origin, "origin");
  y.allow_keys(origin, {"lat", "lon", "alt"});
  w.origin.lat_deg = y.number_in(y.required(origin, "lat"), "lat", -85.0, 85.0);
  w.origin.lon_deg = y.number_in(y.required(origin, "lon"), "lon", -180.0, 180.0);
  if (origin["alt"]) w.origin.alt_m = y.number_in(origin["alt"], "alt", -500.0, 9000.0);

  if (const YAML::Node g = root["geometry"]) {
    y.expect_map(g, "geometry");
    y.allow_keys(g, {"corner_radius", "curb_top_width", "paint_width", "paint_height", "dash_length", "dash_gap",
                     "edge_line_inset", "stop_line_width", "crosswalk_stripe", "crosswalk_gap", "margin"});
    auto& p = w.geometry;
    y.read_number(g, "corner_radius", p.corner_radius, 0.0, 50.0);
    y.read_number(g, "curb_top_width", p.curb_top_width, 0.05, 0.5);
    y.read_number(g, "paint_width", p.paint_width, 0.05, 1.0);
    y.read_number(g, "paint_height", p.paint_height, 0.001, 0.02);
    y.read_number(g, "dash_length", p.dash_length, 0.5, 20.0);
    y.read_number(g, "dash_gap", p.dash_gap, 0.5, 30.0);
    y.read_number(g, "edge_line_inset", p.edge_line_inset, 0.1, 2.0);
    y.read_number(g, "stop_line_width", p.stop_line_width, 0.1, 1.0);
    y.read_number(g, "crosswalk_stripe", p.crosswalk_stripe, 0.2, 1.0);
    y.read_number(g, "crosswalk_gap", p.crosswalk_gap, 0.2, 2.0);
    y.read_number(g, "margin", p.margin, 0.0, 500.0);
  }

  RoadSpec defaults;
  if (const YAML::Node d = root["road_defaults"]) {
    y.expect_map(d, "road_defaults");
    y.allow_keys(d, {ROAD_PROPERTY_KEYS});
    read_road_properties(y, d, defaults);
  }
  const YAML::Node roads = y.required(root, "roads");
  y.expect_sequence(roads, "roads");
  if (roads.size() == 0) y.fail(roads, "a world needs at least one road");
  for (const auto& n : roads) {
    RoadSpec road = read_road(y, n, defaults);
    if (w.road(road.name)) y.fail(n["name"], "road name '" + road.name + "' is used twice");
    w.roads.push_back(std::move(road));
  }

  read_list(y, root, "crosswalks", w.crosswalks, [&](const YAML::Node& n) {
    y.allow_keys(n, {"road", "at", "near", "width"});
    CrosswalkSpec c;
    c.where = yaml_location(y.file(), n);
    c.road = y.string(y.required(n, "road"), "road");
    c.at = read_station(y, n, w, c.road);
    if (n["width"]) c.width = y.number_in(n["width"], "width", 1.0, 20.0);
    return c;
  });
  read_list(y, root, "stop_lines", w.stop_lines, [&](const YAML::Node& n) {
    y.allow_keys(n, {"road", "at", "near", "side"});
    StopLineSpec s;
    s.where = yaml_location(y.file(), n);
    s.road = y.string(y.required(n, "road"), "road");
    s.at = read_station(y, n, w, s.road);
    if (n["side"]) s.side = read_side(y, n["side"]);
    return s;
  });
  read_list(y, root, "buildings", w.buildings, [&](const YAML::Node& n) {
    y.allow_keys(n, {"centre", "size", "yaw_deg", "height", "material"});
    BuildingSpec b;
    b.where = yaml_location(y.file(), n);
    b.centre = y.vec2(y.required(n, "centre"), "centre");
    b.size = y.vec2(y.required(n, "size"), "size");
    if (b.size.minCoeff() < 1.0) y.fail(n["size"], "building size must be at least 1 m each way");
    if (n["yaw_deg"]) b.yaw = y.number_in(n["yaw_deg"], "yaw_deg", -360.0, 360.0) * kDeg;
    if (n["height"]) b.height = y.number_in(n["height"], "height", 2.0, 300.0);
    if (n["material"]) b.material = y.string(n["material"], "material");
    return b;
  });
  read_list(y, root, "poles", w.poles, [&](const YAML::Node& n) {
    y.allow_keys(n, {"road", "side", "spacing", "setback", "start", "height", "sign"});
    PoleRow p;
    read_row(y, n, p);
    if (n["height"]) p.height = y.number_in(n["height"], "height", 1.0, 20.0);
    if (n["sign"]) p.sign = y.boolean(n["sign"], "sign");
    return p;
  });
  read_list(y, root, "trees", w.trees, [&](const YAML::Node& n) {
    y.allow_keys(n, {"road", "side", "spacing", "setback", "start", "height", "crown_radius"});
    TreeRow t;
    read_row(y, n, t);
    if (n["height"]) t.height = y.number_in(n["height"], "height", 2.0, 40.0);
    if (n["crown_radius"]) t.crown_radius = y.number_in(n["crown_radius"], "crown_radius", 0.5, 10.0);
    return t;
  });
  read_list(y, root, "parked_vehicles", w.parked, [&](const YAML::Node& n) {
    y.allow_keys(n, {"type", "position", "yaw_deg"});
    ParkedVehicleSpec p;
    p.where = yaml_location(y.file(), n);
    if (n["type"]) {
      p.type = y.string(n["type"], "type");
      if (!actor_type_from_name(p.type))
        y.fail(n["type"], "unknown vehicle type '" + p.type + "' (expected one of: " + actor_type_names() + ")");
    }
    p.position = y.vec2(y.required(n, "position"), "position");
    if (n["yaw_deg"]) p.yaw = y.number_in(n["yaw_deg"], "yaw_deg", -360.0, 360.0) * kDeg;
    return p;
  });
  check_references(y, root, w);
  return w;
}

}  // namespace

const RoadSpec* WorldDescription::road(const std::string& name) const {
  for (const auto& r : roads)
    if (r.name == name) return &r;
  return nullptr;
}

WorldDescription load_world_description(const std::string& path) { return parse(YamlReader::open(path)); }

WorldDescription parse_world_description(const std::string& yaml_text, const std::string& name) {
  return parse(YamlReader::from_string(yaml_text, name));
}

}  // namespace lidarloop
