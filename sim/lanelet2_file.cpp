#include "sim/lanelet2_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/MGRS.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <pugixml.hpp>

#include "common/input_error.hpp"
#include "common/yaml_reader.hpp"

namespace lidarloop {

const Lanelet2LineString* Lanelet2Map::line(Lanelet2Id id) const {
  const auto it = lines.find(id);
  return it == lines.end() ? nullptr : &it->second;
}

namespace {

// ---------------------------------------------------------------------------------------------------
// Where in the file: pugixml gives byte offsets, a user's editor shows lines.

class Source {
 public:
  Source(std::string name, std::string_view text) : name_(std::move(name)) {
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(i);
  }
  const std::string& name() const { return name_; }
  // "FILE:LINE", or "FILE" when there is no offset.
  std::string where(ptrdiff_t offset) const {
    if (offset < 0) return name_;
    const auto before = std::lower_bound(newlines_.begin(), newlines_.end(), size_t(offset)) - newlines_.begin();
    return name_ + ":" + std::to_string(before + 1);
  }
  [[noreturn]] void fail(ptrdiff_t offset, const std::string& what) const {
    throw InputError(where(offset) + ": " + what);
  }

 private:
  std::string name_;
  std::vector<size_t> newlines_;
};

// A value from the file as it may appear inside a one-line message: control characters replaced, long
// values cut (a fuzzed attribute may be kilobytes of anything).
std::string shown(std::string_view value) {
  constexpr size_t kMax = 40;
  std::string out = "'";
  for (const char c : value.substr(0, kMax)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  if (value.size() > kMax) out += "...";
  return out + "'";
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// A finite number filling the whole text, else nothing ("12abc", "nan" and "" are not numbers).
std::optional<double> to_number(std::string_view s) {
  s = trimmed(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<Lanelet2Id> to_id(std::string_view s) {
  s = trimmed(s);
  Lanelet2Id value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string tag(const Lanelet2Tags& tags, const std::string& key) {
  const auto it = tags.find(key);
  return it == tags.end() ? "" : it->second;
}

// ---------------------------------------------------------------------------------------------------
// The file as written: OSM XML's nodes, ways and relations (LaneletPrimitives.md: points, line strings,
// and lanelets / areas / regulatory elements), before any geometry.

struct RawNode {
  Lanelet2Id id = 0;
  ptrdiff_t offset = -1;
  std::optional<double> lat, lon, local_x, local_y;
  double ele = 0;
};

struct RawWay {
  Lanelet2Id id = 0;
  ptrdiff_t offset = -1;
  Lanelet2Tags tags;
  std::vector<Lanelet2Id> nodes;
};

struct RawMember {
  std::string type, role;
  Lanelet2Id ref = 0;
};

struct RawRelation {
  Lanelet2Id id = 0;
  ptrdiff_t offset = -1;
  Lanelet2Tags tags;
  std::vector<RawMember> members;
};

struct RawFile {
  std::vector<RawNode> nodes;
  std::vector<RawWay> ways;
  std::vector<RawRelation> relations;
};

// "node 12", "way 7", ...: how messages name an element.
std::string named(std::string_view kind, Lanelet2Id id) { return std::string(kind) + " " + std::to_string(id); }

Lanelet2Id read_id(const Source& src, const pugi::xml_node& el) {
  const auto id = to_id(el.attribute("id").value());
  if (!id)
    src.fail(el.offset_debug(),
             std::string("a <") + el.name() + "> without a valid id (" + shown(el.attribute("id").value()) + ")");
  return *id;
}

Lanelet2Tags read_tags(const Source& src, const pugi::xml_node& el, const std::string& label) {
  Lanelet2Tags tags;
  for (const auto& t : el.children("tag")) {
    if (!t.attribute("k")) src.fail(t.offset_debug(), label + ": a <tag> without a key (k)");
    tags[t.attribute("k").value()] = t.attribute("v").value();
  }
  return tags;
}

// JOSM keeps what its user deleted in the saved file, marked action='delete' (the Karlsruhe example
// has such a way); OSM's visible='false' says the same.
bool deleted(const pugi::xml_node& el) {
  return std::string_view(el.attribute("action").value()) == "delete" ||
         std::string_view(el.attribute("visible").value()) == "false";
}

RawNode read_node(const Source& src, const pugi::xml_node& el) {
  RawNode n;
  n.id = read_id(src, el);
  n.offset = el.offset_debug();
  const std::string label = named("node", n.id);
  const auto number = [&](std::string_view key, std::string_view text) {
    const auto value = to_number(text);
    if (!value) src.fail(n.offset, label + ": " + std::string(key) + " " + shown(text) + " is not a number");
    return *value;
  };
  if (const auto a = el.attribute("lat")) n.lat = number("lat", a.value());
  if (const auto a = el.attribute("lon")) n.lon = number("lon", a.value());
  if (n.lat.has_value() != n.lon.has_value()) src.fail(n.offset, label + ": it has one of lat and lon, not both");
  if (n.lat && (std::abs(*n.lat) > 90 || std::abs(*n.lon) > 180))
    src.fail(n.offset, label + ": lat " + shown(el.attribute("lat").value()) + ", lon " +
                           shown(el.attribute("lon").value()) + " is not a place on Earth");
  // Autoware's map tools give each point its coordinates in the map frame as tags (local_x, local_y,
  // ele), beside lat / lon that may be only nominal.
  for (const auto& [key, value] : read_tags(src, el, label)) {
    if (key == "local_x") n.local_x = number(key, value);
    if (key == "local_y") n.local_y = number(key, value);
    if (key == "ele") n.ele = number(key, value);
  }
  if (n.local_x.has_value() != n.local_y.has_value())
    src.fail(n.offset, label + ": it has one of local_x and local_y, not both");
  if (!n.lat && !n.local_x) src.fail(n.offset, label + ": it has neither lat / lon nor local_x / local_y");
  return n;
}

RawWay read_way(const Source& src, const pugi::xml_node& el) {
  RawWay w;
  w.id = read_id(src, el);
  w.offset = el.offset_debug();
  const std::string label = named("way", w.id);
  w.tags = read_tags(src, el, label);
  for (const auto& nd : el.children("nd")) {
    const auto ref = to_id(nd.attribute("ref").value());
    if (!ref) src.fail(nd.offset_debug(), label + ": a node reference " + shown(nd.attribute("ref").value()));
    w.nodes.push_back(*ref);
  }
  return w;
}

RawRelation read_relation(const Source& src, const pugi::xml_node& el) {
  RawRelation r;
  r.id = read_id(src, el);
  r.offset = el.offset_debug();
  const std::string label = named("relation", r.id);
  r.tags = read_tags(src, el, label);
  for (const auto& m : el.children("member")) {
    RawMember member{m.attribute("type").value(), m.attribute("role").value(), 0};
    if (member.type != "node" && member.type != "way" && member.type != "relation")
      src.fail(m.offset_debug(), label + ": a member of type " + shown(member.type) + " (node, way or relation)");
    const auto ref = to_id(m.attribute("ref").value());
    if (!ref) src.fail(m.offset_debug(), label + ": a member reference " + shown(m.attribute("ref").value()));
    member.ref = *ref;
    r.members.push_back(std::move(member));
  }
  return r;
}

RawFile read_osm(const Source& src, const std::string& xml) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(xml.data(), xml.size());
  if (!parsed) src.fail(parsed.offset, std::string("malformed XML: ") + parsed.description());
  // Autoware's map tools write <osm> without OSM's version attribute: nothing here asks for it.
  const pugi::xml_node osm = doc.child("osm");
  if (!osm) src.fail(-1, "no <osm> element: not an OSM XML file");
  RawFile file;
  for (const auto& el : osm.children()) {  // <bounds>, Autoware's <MetaInfo> and others say nothing of geometry
    const std::string_view name = el.name();
    if (deleted(el)) continue;
    if (name == "node") file.nodes.push_back(read_node(src, el));
    if (name == "way") file.ways.push_back(read_way(src, el));
    if (name == "relation") file.relations.push_back(read_relation(src, el));
  }
  return file;
}

// Ids are unique per kind in OSM; a second element of the same id would silently replace the first.
template <typename Raw>
std::unordered_map<Lanelet2Id, const Raw*> index_by_id(const Source& src, const std::vector<Raw>& elements,
                                                       std::string_view kind) {
  std::unordered_map<Lanelet2Id, const Raw*> index;
  for (const Raw& e : elements) {
    const auto [it, added] = index.emplace(e.id, &e);
    if (!added)
      src.fail(e.offset, named(kind, e.id) + ": a second " + std::string(kind) + " of this id (the first at " +
                             src.where(it->second->offset) + ")");
  }
  return index;
}

// ---------------------------------------------------------------------------------------------------
// Autoware's map_projector_info.yaml (autoware_map_msgs/MapProjectorInfo, map_projection_loader's
// README): in which frame the nodes' local_x / local_y are.

struct Projector {
  Lanelet2Coordinates type = Lanelet2Coordinates::local;
  std::optional<Geodetic> origin;  // map_origin (TransverseMercator, LocalCartesianUTM), the grid's corner (MGRS)
  double scale_factor = 0.9996;    // TransverseMercator's; MapProjectorInfo's default
  int zone = 0;                    // UTM zone (LocalCartesianUTM, MGRS); 0 is UPS
  bool northp = true;
  double easting = 0, northing = 0;  // of local_x = local_y = 0 in that zone (or on the TM's meridian)
};

Geodetic read_map_origin(const YamlReader& y, const YAML::Node& node) {
  YamlMap m(y, node, "map_origin");
  Geodetic g;
  g.lat_deg = y.number_in(m.required("latitude"), "latitude", -90, 90);
  g.lon_deg = y.number_in(m.required("longitude"), "longitude", -180, 180);
  m.number("altitude", g.alt_m, -11'000, 100'000);
  m.done();
  return g;
}

Projector read_projector(const std::string& path) {
  const YamlReader y = YamlReader::open(path);
  YamlMap m(y, y.root(), "map_projector_info");
  const YAML::Node type_node = m.required("projector_type");
  const std::string type = y.string(type_node, "projector_type");
  std::string datum = "WGS84", grid;
  std::optional<double> scale;
  m.string("vertical_datum", datum).string("mgrs_grid", grid).number("scale_factor", scale, 0.5, 2.0);
  const YAML::Node origin_node = m["map_origin"];
  m.done();
  // Heights are taken as written (`ele` is z): no geoid model is applied, whichever datum is declared.
  if (datum != "WGS84" && datum != "EGM2008")
    y.fail(m["vertical_datum"], "vertical_datum must be WGS84 or EGM2008, got " + shown(datum));

  Projector p;
  const std::string kind = lower(type);  // Autoware's README writes "local" where the message says "Local"
  if (kind == "transversemercator") {
    p.type = Lanelet2Coordinates::transverse_mercator;
    p.origin = read_map_origin(y, m.required("map_origin"));
    p.scale_factor = scale.value_or(0.9996);
    const GeographicLib::TransverseMercator tm(GeographicLib::Constants::WGS84_a(), GeographicLib::Constants::WGS84_f(),
                                               p.scale_factor);
    tm.Forward(p.origin->lon_deg, p.origin->lat_deg, p.origin->lon_deg, p.easting, p.northing);
  } else if (kind == "localcartesianutm") {
    p.type = Lanelet2Coordinates::local_cartesian_utm;
    p.origin = read_map_origin(y, m.required("map_origin"));
    try {
      GeographicLib::UTMUPS::Forward(p.origin->lat_deg, p.origin->lon_deg, p.zone, p.northp, p.easting, p.northing);
    } catch (const GeographicLib::GeographicErr& e) {
      y.fail(origin_node, std::string("map_origin has no UTM coordinates: ") + e.what());
    }
  } else if (kind == "mgrs") {
    p.type = Lanelet2Coordinates::mgrs;
    const YAML::Node grid_node = m.required("mgrs_grid");
    try {
      int precision = 0;
      // The grid square's south-west corner (centerp false): Autoware's local_x / local_y are metres
      // from it within the square's UTM zone.
      GeographicLib::MGRS::Reverse(grid, p.zone, p.northp, p.easting, p.northing, precision, false);
      Geodetic corner;
      GeographicLib::UTMUPS::Reverse(p.zone, p.northp, p.easting, p.northing, corner.lat_deg, corner.lon_deg);
      p.origin = corner;
    } catch (const GeographicLib::GeographicErr& e) {
      y.fail(grid_node, "mgrs_grid " + shown(grid) + " is not an MGRS grid square: " + e.what());
    }
  } else if (kind == "local") {
    p.type = Lanelet2Coordinates::local;
  } else {
    y.fail(type_node,
           "projector_type " + shown(type) + " is not one of TransverseMercator, LocalCartesianUTM, MGRS, Local");
  }
  return p;
}

// local_x / local_y in the projector's frame to WGS-84 lat / lon (the inverse of Autoware's projectors).
// Throws GeographicLib::GeographicErr where the projection has no such point.
Eigen::Vector2d projected_to_wgs84(const Projector& p, const GeographicLib::TransverseMercator& tm, double x,
                                   double y) {
  double lat = 0, lon = 0;
  if (p.type == Lanelet2Coordinates::transverse_mercator) {
    tm.Reverse(p.origin->lon_deg, p.easting + x, p.northing + y, lat, lon);
  } else {
    GeographicLib::UTMUPS::Reverse(p.zone, p.northp, p.easting + x, p.northing + y, lat, lon);
  }
  if (!std::isfinite(lat) || !std::isfinite(lon)) throw GeographicLib::GeographicErr("not a place on Earth");
  return {lat, lon};
}

// ---------------------------------------------------------------------------------------------------
// Nodes into the world's frame.

// A node's position before the world's origin is known: lat / lon, or already the world's metres.
struct Placed {
  bool metres = false;
  Eigen::Vector2d value;  // (lat, lon) or (x, y)
  double ele = 0;
  const RawNode* node = nullptr;
};

std::vector<Placed> place_nodes(const Source& src, const RawFile& file, const std::optional<Projector>& projector,
                                Lanelet2Coordinates& coordinates) {
  std::vector<Placed> placed;
  placed.reserve(file.nodes.size());
  if (projector) {
    coordinates = projector->type;
    const GeographicLib::TransverseMercator tm(GeographicLib::Constants::WGS84_a(), GeographicLib::Constants::WGS84_f(),
                                               projector->scale_factor);
    for (const RawNode& n : file.nodes) {
      Placed p{false, {}, n.ele, &n};
      if (!n.local_x) {  // a node with lat / lon only: those are WGS-84 whatever the projector
        p.value = {*n.lat, *n.lon};
      } else if (projector->type == Lanelet2Coordinates::local) {
        p = {true, {*n.local_x, *n.local_y}, n.ele, &n};
      } else {
        try {
          p.value = projected_to_wgs84(*projector, tm, *n.local_x, *n.local_y);
        } catch (const GeographicLib::GeographicErr& e) {
          src.fail(n.offset, named("node", n.id) + ": local_x " + std::to_string(*n.local_x) + ", local_y " +
                                 std::to_string(*n.local_y) + " is outside the projection: " + e.what());
        }
      }
      placed.push_back(p);
    }
    return placed;
  }
  // No projector file: lat / lon when the file has them; a file with local_x / local_y only is in
  // the world's metres (Local).
  const bool wgs84 = std::any_of(file.nodes.begin(), file.nodes.end(), [](const RawNode& n) { return n.lat; });
  coordinates = wgs84 ? Lanelet2Coordinates::wgs84 : Lanelet2Coordinates::local;
  for (const RawNode& n : file.nodes) {
    if (wgs84 && !n.lat)
      src.fail(n.offset, named("node", n.id) +
                             ": it has no lat / lon, and without a map_projector_info.yaml its local_x / local_y "
                             "cannot be placed among the other nodes' lat / lon");
    placed.push_back(wgs84 ? Placed{false, {*n.lat, *n.lon}, n.ele, &n}
                           : Placed{true, {*n.local_x, *n.local_y}, n.ele, &n});
  }
  return placed;
}

// The middle of the lat / lon bounding box of the nodes that have one.
Geodetic bounding_box_centre(const std::vector<Placed>& placed) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e9), hi = -lo;
  for (const Placed& p : placed)
    if (!p.metres) lo = lo.cwiseMin(p.value), hi = hi.cwiseMax(p.value);
  if (lo.x() > hi.x()) return {};
  return {0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), 0};
}

Geodetic choose_origin(const Lanelet2ReadOptions& options, const std::optional<Projector>& projector,
                       const std::vector<Placed>& placed, std::vector<std::string>& warnings) {
  if (options.origin) return *options.origin;
  if (projector && projector->origin) return *projector->origin;
  if (projector || std::all_of(placed.begin(), placed.end(), [](const Placed& p) { return p.metres; })) {
    if (!placed.empty())
      warnings.push_back(
          "the map's local_x / local_y are in a Local frame with no geographic origin: the world is "
          "placed at lat 0, lon 0 (give an origin to place it on Earth)");
    return {};
  }
  return bounding_box_centre(placed);
}

// Points far from the origin are taken for a broken file. The node named is the one farthest from the
// bulk of the map (the median point), so that a stray node at lat 0, lon 0 is named rather than the map
// around an origin that stray node has pulled away.
void check_extent(const Source& src, const std::vector<Placed>& placed, const std::vector<Eigen::Vector3d>& points,
                  const Geodetic& origin, double max_extent_m) {
  std::vector<size_t> far;
  for (size_t i = 0; i < points.size(); ++i)
    if (!(points[i].head<2>().norm() <= max_extent_m)) far.push_back(i);  // NaN is far
  if (far.empty()) return;
  std::vector<double> xs, ys;
  for (const auto& p : points)
    if (std::isfinite(p.x()) && std::isfinite(p.y())) xs.push_back(p.x()), ys.push_back(p.y());
  Eigen::Vector2d median = Eigen::Vector2d::Zero();
  if (!xs.empty()) {
    std::nth_element(xs.begin(), xs.begin() + long(xs.size() / 2), xs.end());
    std::nth_element(ys.begin(), ys.begin() + long(ys.size() / 2), ys.end());
    median = {xs[xs.size() / 2], ys[ys.size() / 2]};
  }
  const size_t worst = *std::max_element(far.begin(), far.end(), [&](size_t a, size_t b) {
    const double da = (points[a].head<2>() - median).norm(), db = (points[b].head<2>() - median).norm();
    return std::isnan(db) ? !std::isnan(da) : da < db;
  });
  std::ostringstream what;
  what.precision(6);
  what << named("node", placed[worst].node->id) << ": " << points[worst].head<2>().norm() / 1000
       << " km from the map's origin (lat " << origin.lat_deg << ", lon " << origin.lon_deg
       << "), farther than a map of one operating area reaches (" << max_extent_m / 1000 << " km)";
  src.fail(placed[worst].node->offset, what.str());
}

// ---------------------------------------------------------------------------------------------------
// Geometry of lanelet bounds.

using Points = std::vector<Eigen::Vector3d>;

double cross2(const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); }

// Distance from `p` to the line string, positive when p is left of it (Lanelet2's signedDistance).
double signed_distance(const Points& line, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity(), side = 0;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector2d a = line[i].head<2>(), ab = line[i + 1].head<2>() - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    const double d = (p - (a + t * ab)).norm();
    if (d < best) best = d, side = cross2(ab, p - a);
  }
  return side >= 0 ? best : -best;
}

// Lanelet2's geometry::align takes a bound's middle point (its middle vertex, or the middle of its only
// segment) to tell which side of the other bound it is on.
Eigen::Vector2d middle(const Points& line) {
  return line.size() > 2 ? Eigen::Vector2d(line[line.size() / 2].head<2>())
                         : Eigen::Vector2d(0.5 * (line.front() + line.back()).head<2>());
}

struct Segment {
  Eigen::Vector2d a, b;
  double lo = 0, hi = 0;  // extent along the sweep axis
  int bound = 0;          // 0 left, 1 right
};

// Where segments s and t cross inside both. Touching (a shared node where bounds meet at a merge, an
// end on the other segment) is not crossing: both sides of each segment must be strictly apart.
std::optional<Eigen::Vector2d> crossing(const Segment& s, const Segment& t) {
  const Eigen::Vector2d r = s.b - s.a, q = t.b - t.a;
  const double d1 = cross2(r, t.a - s.a), d2 = cross2(r, t.b - s.a);
  const double d3 = cross2(q, s.a - t.a), d4 = cross2(q, s.b - t.a);
  if (!((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) || !((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return std::nullopt;
  return Eigen::Vector2d(s.a + d3 / (d3 - d4) * r);
}

// The first crossing of the two line strings found by a sweep along the axis they extend most in, so
// that long bounds of many points cost about their length, not the product of their sizes.
std::optional<Eigen::Vector2d> first_crossing(const Points& left, const Points& right) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Points* line : {&left, &right})
    for (const auto& p : *line) lo = lo.cwiseMin(p.head<2>()), hi = hi.cwiseMax(p.head<2>());
  const int axis = (hi - lo).x() >= (hi - lo).y() ? 0 : 1;
  std::vector<Segment> segments;
  for (int bound = 0; bound < 2; ++bound) {
    const Points& line = bound == 0 ? left : right;
    for (size_t i = 0; i + 1 < line.size(); ++i) {
      Segment s{line[i].head<2>(), line[i + 1].head<2>(), 0, 0, bound};
      s.lo = std::min(s.a[axis], s.b[axis]), s.hi = std::max(s.a[axis], s.b[axis]);
      segments.push_back(s);
    }
  }
  std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) { return a.lo < b.lo; });
  std::vector<Segment> active[2];
  for (const Segment& s : segments) {
    auto& other = active[1 - s.bound];
    std::erase_if(other, [&](const Segment& o) { return o.hi < s.lo; });
    for (const Segment& o : other)
      if (auto x = crossing(s, o)) return x;
    active[s.bound].push_back(s);
  }
  return std::nullopt;
}

// Lanelet2 lets a lanelet use a line string as a bound in either direction, so that neighbouring
// lanelets of opposite directions share their common bound (LaneletPrimitives.md, "Lanelet"; the loader
// calls geometry::align). Here both bounds come out running the lanelet's way:
// - the bounds run opposite ways when their first points are farther apart than each first point is
//   from the other bound's last (summed over both ends, which also keeps the closing edges from
//   crossing); then one is reversed, the one Lanelet2's align reverses: the right bound when it lies
//   right of the left bound as written, else the left;
// - bounds running the same way with the right one on the left side are both reversed (align does
//   that too): the lanelet runs against both of its ways.
void orient_bounds(Lanelet2Lanelet& ll) {
  Points &left = ll.left_points, &right = ll.right_points;
  const auto d = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).head<2>().norm(); };
  const bool opposite = d(left.front(), right.front()) + d(left.back(), right.back()) >
                        d(left.front(), right.back()) + d(left.back(), right.front());
  const bool right_is_right = signed_distance(left, middle(right)) < 0;
  if (opposite && right_is_right) {
    std::reverse(right.begin(), right.end()), ll.right_inverted = true;
  } else if (opposite) {
    std::reverse(left.begin(), left.end()), ll.left_inverted = true;
  } else if (signed_distance(left, middle(right)) > 0 && signed_distance(right, middle(left)) < 0) {
    std::reverse(left.begin(), left.end()), ll.left_inverted = true;
    std::reverse(right.begin(), right.end()), ll.right_inverted = true;
  }
}

// ---------------------------------------------------------------------------------------------------
// Relations.

struct Elements {
  const std::unordered_map<Lanelet2Id, size_t>& nodes;  // id -> index into the points
  const std::map<Lanelet2Id, Lanelet2LineString>& lines;
  const std::unordered_map<Lanelet2Id, const RawRelation*>& relations;
};

// How a message names a member: a lanelet's bounds by their role, anything else by role and type.
std::string member_label(const RawRelation& r, const RawMember& m) {
  if (tag(r.tags, "type") == "lanelet") {
    if (m.role == "left" || m.role == "right") return "its " + m.role + " bound " + std::to_string(m.ref);
    if (m.role == "centerline") return "its centerline " + std::to_string(m.ref);
    if (m.role == "regulatory_element") return "its regulatory element " + std::to_string(m.ref);
  }
  return "its member " + m.type + " " + std::to_string(m.ref) + " (role " + shown(m.role) + ")";
}

std::string relation_label(const RawRelation& r) {
  const std::string type = tag(r.tags, "type");
  if (type == "lanelet") return named("lanelet", r.id);
  if (type == "multipolygon") return named("multipolygon", r.id);
  if (type == "regulatory_element") return named("regulatory element", r.id);
  return named("relation", r.id);
}

// Every member must be an element of the file (Lanelet2's loader would put an empty dummy in its place).
void check_members(const Source& src, const RawRelation& r, const Elements& e) {
  for (const RawMember& m : r.members) {
    const bool found = m.type == "node"  ? e.nodes.count(m.ref) > 0
                       : m.type == "way" ? e.lines.count(m.ref) > 0
                                         : e.relations.count(m.ref) > 0;
    if (!found)
      src.fail(r.offset, relation_label(r) + ": " + member_label(r, m) + " is not a " + m.type + " of the file");
  }
}

// The one member of `role`, which must be a `type`; none is nullptr.
const RawMember* single_member(const Source& src, const RawRelation& r, const std::string& role,
                               const std::string& type) {
  const RawMember* found = nullptr;
  for (const RawMember& m : r.members) {
    if (m.role != role) continue;
    if (found) src.fail(r.offset, relation_label(r) + ": it has more than one member of role " + shown(role));
    if (m.type != type)
      src.fail(r.offset, relation_label(r) + ": " + member_label(r, m) + " is a " + m.type + ", not a " + type);
    found = &m;
  }
  return found;
}

// speed_limit as Lanelet2 writes velocities: a number and a unit, km/h when none (LaneletAndAreaTagging.md).
std::optional<double> speed_mps(std::string_view text) {
  text = trimmed(text);
  size_t split = 0;
  while (split < text.size() && (std::isdigit(static_cast<unsigned char>(text[split])) || text[split] == '.')) ++split;
  const auto value = to_number(text.substr(0, split));
  if (!value || *value < 0) return std::nullopt;
  const std::string unit = lower(std::string(trimmed(text.substr(split))));
  if (unit.empty() || unit == "km/h" || unit == "kmh" || unit == "kph") return *value / 3.6;
  if (unit == "mph") return *value * 0.44704;
  if (unit == "m/s" || unit == "mps") return *value;
  return std::nullopt;
}

Lanelet2Lanelet make_lanelet(const Source& src, const RawRelation& r,
                             const std::map<Lanelet2Id, Lanelet2LineString>& lines,
                             std::vector<std::string>& warnings) {
  Lanelet2Lanelet ll;
  ll.id = r.id;
  ll.tags = r.tags;
  ll.where = src.where(r.offset);
  ll.subtype = tag(r.tags, "subtype");
  ll.location = tag(r.tags, "location");
  const std::string label = named("lanelet", r.id);
  // LaneletPrimitives.md: a lanelet has exactly one left and one right bound.
  const RawMember* left = single_member(src, r, "left", "way");
  const RawMember* right = single_member(src, r, "right", "way");
  if (!left) src.fail(r.offset, label + ": it has no left bound (a way member of role left)");
  if (!right) src.fail(r.offset, label + ": it has no right bound (a way member of role right)");
  if (const RawMember* centre = single_member(src, r, "centerline", "way")) ll.centerline = centre->ref;
  for (const RawMember& m : r.members)
    if (m.role == "regulatory_element") {
      if (m.type != "relation")
        src.fail(r.offset, label + ": " + member_label(r, m) + " is a " + m.type + ", not a relation");
      ll.regulatory_elements.push_back(m.ref);
    }
  ll.left = left->ref, ll.right = right->ref;
  ll.left_points = lines.at(ll.left).points;
  ll.right_points = lines.at(ll.right).points;
  if (ll.left == ll.right) warnings.push_back(ll.where + ": " + label + ": its left and right bound are the same way");

  const std::string one_way = lower(tag(r.tags, "one_way"));
  ll.one_way = one_way != "no" && one_way != "false";
  if (const std::string limit = tag(r.tags, "speed_limit"); !limit.empty()) {
    ll.speed_limit_mps = speed_mps(limit);
    if (!ll.speed_limit_mps)
      warnings.push_back(ll.where + ": " + label + ": speed_limit " + shown(limit) + " is not a speed; ignored");
  }

  orient_bounds(ll);
  if (const auto x = first_crossing(ll.left_points, ll.right_points)) {
    std::ostringstream what;
    what.setf(std::ios::fixed), what.precision(2);
    what << label << ": its left bound " << ll.left << " and right bound " << ll.right << " cross each other at ("
         << x->x() << ", " << x->y() << ")";
    if (ll.left_inverted != ll.right_inverted)
      what << " (with the " << (ll.left_inverted ? "left" : "right")
           << " bound reversed, as their ends say they run opposite ways)";
    src.fail(r.offset, what.str());
  }
  return ll;
}

// Joins an area's outer (or inner) ways end to end into closed rings, reversing ways as needed, as
// Lanelet2's loader does (LaneletAndAreaTagging.md, "Areas"): ways meet at shared nodes.
std::vector<std::vector<Eigen::Vector3d>> join_rings(const Source& src, const RawRelation& r,
                                                     const std::vector<Lanelet2Id>& way_ids,
                                                     const std::map<Lanelet2Id, Lanelet2LineString>& lines,
                                                     const std::string& role) {
  std::unordered_multimap<Lanelet2Id, size_t> by_end;  // node id of a way's end -> the way's index
  for (size_t i = 0; i < way_ids.size(); ++i) {
    const auto& ids = lines.at(way_ids[i]).point_ids;
    by_end.emplace(ids.front(), i);
    if (ids.back() != ids.front()) by_end.emplace(ids.back(), i);
  }
  std::vector<bool> used(way_ids.size(), false);
  std::vector<std::vector<Eigen::Vector3d>> rings;
  for (size_t start = 0; start < way_ids.size(); ++start) {
    if (used[start]) continue;
    used[start] = true;
    const Lanelet2LineString* last = &lines.at(way_ids[start]);
    std::vector<Lanelet2Id> ids = last->point_ids;
    std::vector<Eigen::Vector3d> ring = last->points;
    while (ids.back() != ids.front()) {
      const auto [first, end] = by_end.equal_range(ids.back());
      const auto next = std::find_if(first, end, [&](const auto& entry) { return !used[entry.second]; });
      if (next == end)
        src.fail(r.offset, named("multipolygon", r.id) + ": its " + role + " ring does not close: way " +
                               std::to_string(last->id) + " ends at node " + std::to_string(ids.back()) +
                               ", where no other " + role + " way of the relation starts or ends");
      used[next->second] = true;
      last = &lines.at(way_ids[next->second]);
      const bool reversed = last->point_ids.front() != ids.back();
      for (size_t k = 1; k < last->point_ids.size(); ++k) {
        const size_t j = reversed ? last->point_ids.size() - 1 - k : k;
        ids.push_back(last->point_ids[j]);
        ring.push_back(last->points[j]);
      }
    }
    ring.pop_back();  // the first point, not repeated
    if (ring.size() < 3)
      src.fail(r.offset, named("multipolygon", r.id) + ": its " + role + " ring through way " +
                             std::to_string(way_ids[start]) + " has fewer than 3 points");
    rings.push_back(std::move(ring));
  }
  return rings;
}

Lanelet2Area make_area(const Source& src, const RawRelation& r, const std::map<Lanelet2Id, Lanelet2LineString>& lines) {
  Lanelet2Area area;
  area.id = r.id;
  area.tags = r.tags;
  area.subtype = tag(r.tags, "subtype");
  area.where = src.where(r.offset);
  for (const RawMember& m : r.members) {
    if (m.role != "outer" && m.role != "inner") continue;  // regulatory elements of the area, ...
    if (m.type != "way")
      src.fail(r.offset, named("multipolygon", r.id) + ": " + member_label(r, m) + " is a " + m.type + ", not a way");
    (m.role == "outer" ? area.outer_ways : area.inner_ways).push_back(m.ref);
  }
  if (area.outer_ways.empty()) src.fail(r.offset, named("multipolygon", r.id) + ": it has no outer way");
  area.outer = join_rings(src, r, area.outer_ways, lines, "outer");
  area.inner = join_rings(src, r, area.inner_ways, lines, "inner");
  return area;
}

Lanelet2Regulatory make_regulatory(const Source& src, const RawRelation& r) {
  Lanelet2Regulatory reg;
  reg.id = r.id;
  reg.tags = r.tags;
  reg.subtype = tag(r.tags, "subtype");
  reg.where = src.where(r.offset);
  for (const RawMember& m : r.members) reg.members[m.role].push_back(m.ref);
  return reg;
}

// The region tag most lanelets carry (Autoware and the Lanelet2 examples tag each lanelet, e.g. "de").
std::string most_common_region(const std::vector<Lanelet2Lanelet>& lanelets) {
  std::map<std::string, int> count;
  for (const auto& ll : lanelets)
    if (const std::string region = lower(tag(ll.tags, "region")); !region.empty()) ++count[region];
  std::string best;
  int most = 0;
  for (const auto& [region, n] : count)
    if (n > most) best = region, most = n;
  return best;
}

Lanelet2Map parse(const std::string& xml, const std::string& name, const Lanelet2ReadOptions& options,
                  const std::optional<Projector>& projector) {
  const Source src(name, xml);
  const RawFile file = read_osm(src, xml);
  index_by_id(src, file.nodes, "node");
  index_by_id(src, file.ways, "way");
  const auto relations = index_by_id(src, file.relations, "relation");

  Lanelet2Map map;
  map.file = name;
  const std::vector<Placed> placed = place_nodes(src, file, projector, map.coordinates);
  map.origin = choose_origin(options, projector, placed, map.warnings);
  const LocalFrame frame(map.origin);
  std::vector<Eigen::Vector3d> points;
  std::unordered_map<Lanelet2Id, size_t> node_index;
  for (const Placed& p : placed) {
    const Eigen::Vector2d xy = p.metres ? p.value : frame.to_local(p.value.x(), p.value.y());
    node_index.emplace(p.node->id, points.size());
    points.emplace_back(xy.x(), xy.y(), p.ele);
  }
  // An MGRS map about its grid square's corner reaches across the square (100 km, the diagonal 141 km)
  // before its own extent counts.
  const bool about_corner = !options.origin && projector && projector->type == Lanelet2Coordinates::mgrs;
  check_extent(src, placed, points, map.origin, options.max_extent_m + (about_corner ? 100'000 * std::sqrt(2.0) : 0));

  for (const RawWay& w : file.ways) {
    Lanelet2LineString line;
    line.id = w.id;
    line.tags = w.tags;
    line.type = tag(w.tags, "type");  // what a line string is: LinestringTagging.md's type and subtype
    line.subtype = tag(w.tags, "subtype");
    line.where = src.where(w.offset);
    for (const Lanelet2Id ref : w.nodes) {
      const auto it = node_index.find(ref);
      if (it == node_index.end())
        src.fail(w.offset, named("way", w.id) + ": its node " + std::to_string(ref) + " is not a node of the file");
      line.point_ids.push_back(ref);
      line.points.push_back(points[it->second]);
    }
    // LaneletPrimitives.md: a line string is an ordered list of at least two points.
    if (line.points.size() < 2)
      src.fail(w.offset, named("way", w.id) + ": a line string of " + std::to_string(line.points.size()) +
                             (line.points.size() == 1 ? " point" : " points") + " (it needs at least 2)");
    map.lines.emplace(w.id, std::move(line));
  }

  const Elements elements{node_index, map.lines, relations};
  for (const RawRelation& r : file.relations) {
    check_members(src, r, elements);
    const std::string type = tag(r.tags, "type");
    if (type == "lanelet") {
      map.lanelets.push_back(make_lanelet(src, r, map.lines, map.warnings));
    } else if (type == "multipolygon") {
      map.areas.push_back(make_area(src, r, map.lines));
    } else if (type == "regulatory_element") {
      map.regulatory.push_back(make_regulatory(src, r));
    } else {
      ++map.other_relations[type.empty() ? "(no type)" : type];
    }
  }
  if (map.lanelets.empty()) src.fail(-1, "no lanelets (relations tagged type=lanelet): not a Lanelet2 map");
  map.country = most_common_region(map.lanelets);
  return map;
}

}  // namespace

Lanelet2Map parse_lanelet2(const std::string& xml, const std::string& name, const Lanelet2ReadOptions& options) {
  return parse(xml, name, options, std::nullopt);
}

Lanelet2Map read_lanelet2(const std::string& path, const Lanelet2ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read the file");
  // Autoware keeps the projection beside the map (map_projection_loader: map_projector_info.yaml in the
  // map's folder).
  std::optional<Projector> projector;
  const std::filesystem::path info = std::filesystem::path(path).parent_path() / "map_projector_info.yaml";
  std::error_code error;
  if (std::filesystem::is_regular_file(info, error)) projector = read_projector(info.string());
  return parse(text.str(), path, options, projector);
}

}  // namespace lidarloop
