#include "sim/opendrive_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <pugixml.hpp>

#include "common/input_error.hpp"
#include "sim/opendrive_geometry.hpp"

namespace lidarloop {

const OdrLane* OdrLaneSection::lane(int id) const {
  if (id == 0) return &center;
  const auto& side = id > 0 ? left : right;
  for (const auto& l : side)
    if (l.id == id) return &l;
  return nullptr;
}

size_t OdrRoad::section_at(double s) const {
  size_t i = 0;
  while (i + 1 < sections.size() && sections[i + 1].s <= s + 1e-9) ++i;
  return i;
}

const OdrRoad* OdrMap::road(const std::string& id) const {
  const auto it = road_index.find(id);
  return it == road_index.end() ? nullptr : &roads[it->second];
}

namespace {

constexpr int kFoldSamples = 64;          // tangents checked along a poly3 / paramPoly3 for folding back
constexpr double kMaxWidth = 1000;        // m: lane widths, borders and offsets beyond this are broken values
constexpr double kMaxRepeatLength = 1e5;  // m: an object's repeat longer than this is a broken value
constexpr int kMaxRepeatCopies = 10000;   // copies of one repeated object: more is a broken distance
constexpr double kMaxCurvature = 100;     // 1/m: a 1 cm radius

// Messages name the file and line of the element, the road and the s where it went wrong.
class Where {
 public:
  Where(std::string name, std::string_view text) : name_(std::move(name)) {
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(i);
  }
  const std::string& file() const { return name_; }
  int line(const pugi::xml_node& n) const {
    const ptrdiff_t at = n.offset_debug();
    if (at < 0) return 0;
    return int(std::lower_bound(newlines_.begin(), newlines_.end(), size_t(at)) - newlines_.begin()) + 1;
  }
  std::string at(const pugi::xml_node& n) const {
    const int l = line(n);
    return l > 0 ? name_ + ":" + std::to_string(l) : name_;
  }
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& road, std::optional<double> s,
                         const std::string& what) const {
    fail_at(at(n), road, s, what);
  }
  std::string at_line(int line) const { return line > 0 ? name_ + ":" + std::to_string(line) : name_; }
  [[noreturn]] void fail_at(const std::string& place, const std::string& road, std::optional<double> s,
                            const std::string& what) const {
    std::ostringstream o;
    o << place << ": ";
    if (!road.empty()) o << "road " << road << (s ? "" : ": ");
    if (s) o << (road.empty() ? "" : " ") << "at s=" << *s << ": ";
    o << what;
    throw InputError(o.str());
  }

 private:
  std::string name_;
  std::vector<size_t> newlines_;
};

// A value as it may appear in a one-line message: control characters replaced, long values cut.
std::string quoted(std::string_view v) {
  std::string out = "'";
  for (const char c : v.substr(0, 40)) out += static_cast<unsigned char>(c) < 0x20 ? '?' : c;
  return out + (v.size() > 40 ? "...'" : "'");
}

std::optional<double> parse_number(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '+')) s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// Reads one road (or junction) with its context for messages.
struct Reader {
  const Where& where;
  std::string road;  // id of the road being read ("" outside one)

  std::optional<double> maybe(const pugi::xml_node& n, const char* key) const {
    const pugi::xml_attribute a = n.attribute(key);
    if (!a) return std::nullopt;
    const auto v = parse_number(a.value());
    if (!v)
      where.fail(n, road, std::nullopt, std::string(n.name()) + " " + key + " is not a number: " + quoted(a.value()));
    return v;
  }
  double number(const pugi::xml_node& n, const char* key, double fallback) const {
    return maybe(n, key).value_or(fallback);
  }
  double required(const pugi::xml_node& n, const char* key) const {
    const auto v = maybe(n, key);
    if (!v) where.fail(n, road, std::nullopt, std::string(n.name()) + " has no " + key);
    return *v;
  }
  // Lane ids and revision numbers: whole and within +-kMaxWhole, so that the int they become holds them
  // (a fuzzed 7e114 converted to int is undefined behaviour).
  static constexpr double kMaxWhole = 1e6;
  int whole(const pugi::xml_node& n, const char* key, double v, double lowest, const char* what) const {
    if (v != std::floor(v) || v < lowest || v > kMaxWhole)
      where.fail(n, road, std::nullopt,
                 std::string(n.name()) + " " + key + " is not " + what + ": " + quoted(n.attribute(key).value()));
    return int(v);
  }
  int revision(const pugi::xml_node& n, const char* key, int fallback) const {
    return whole(n, key, number(n, key, fallback), 0, "a revision number");
  }
  int integer(const pugi::xml_node& n, const char* key) const {
    return whole(n, key, required(n, key), -kMaxWhole, "a lane id");
  }
  OdrCubic cubic(const pugi::xml_node& n, const char* s_key, double base) const {
    return {base + required(n, s_key), number(n, "a", 0), number(n, "b", 0), number(n, "c", 0), number(n, "d", 0)};
  }
  // Records sorted by s (files list them in order; a stable sort keeps a later duplicate last).
  std::vector<OdrCubic> cubics(const pugi::xml_node& parent, const char* child, const char* s_key, double base) const {
    std::vector<OdrCubic> out;
    for (const auto& n : parent.children(child)) out.push_back(cubic(n, s_key, base));
    std::stable_sort(out.begin(), out.end(), [](const OdrCubic& a, const OdrCubic& b) { return a.s < b.s; });
    return out;
  }
};

// The smallest value of a cubic over [s0, s1]: at an end or where its slope is zero.
double cubic_min(const OdrCubic& c, double s0, double s1) {
  double lo = std::min(c.at(s0), c.at(s1));
  // slope b + 2c x + 3d x^2 = 0, x = s - c.s
  const double A = 3 * c.d, B = 2 * c.c, C = c.b;
  auto check = [&](double x) {
    const double s = c.s + x;
    if (s > s0 && s < s1) lo = std::min(lo, c.at(s));
  };
  if (std::abs(A) < 1e-15) {
    if (std::abs(B) > 1e-15) check(-C / B);
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      check((-B + std::sqrt(disc)) / (2 * A));
      check((-B - std::sqrt(disc)) / (2 * A));
    }
  }
  return lo;
}

OdrGeometry read_geometry(const Reader& r, const pugi::xml_node& n) {
  OdrGeometry g;
  g.s = r.required(n, "s");
  g.x = r.required(n, "x");
  g.y = r.required(n, "y");
  g.hdg = r.required(n, "hdg");
  g.length = r.required(n, "length");
  if (g.length < 0 || g.length > 1e6)
    r.where.fail(n, r.road, g.s, "geometry length " + std::to_string(g.length) + " m");
  const pugi::xml_node shape = n.first_child();
  const std::string kind = shape ? shape.name() : "";
  if (kind == "line") {
    g.kind = OdrGeometryKind::line;
  } else if (kind == "arc") {
    g.kind = OdrGeometryKind::arc;
    g.curvature = r.required(shape, "curvature");
    if (std::abs(g.curvature) > kMaxCurvature) r.where.fail(shape, r.road, g.s, "arc curvature beyond 100 1/m");
  } else if (kind == "spiral") {
    g.kind = OdrGeometryKind::spiral;
    g.curv_start = r.required(shape, "curvStart");
    g.curv_end = r.required(shape, "curvEnd");
    if (std::abs(g.curv_start) > kMaxCurvature || std::abs(g.curv_end) > kMaxCurvature)
      r.where.fail(shape, r.road, g.s, "spiral curvature beyond 100 1/m");
  } else if (kind == "poly3") {
    g.kind = OdrGeometryKind::poly3;
    g.a = r.number(shape, "a", 0), g.b = r.number(shape, "b", 0);
    g.c = r.number(shape, "c", 0), g.d = r.number(shape, "d", 0);
  } else if (kind == "paramPoly3") {
    g.kind = OdrGeometryKind::param_poly3;
    g.au = r.number(shape, "aU", 0), g.bu = r.number(shape, "bU", 0);
    g.cu = r.number(shape, "cU", 0), g.du = r.number(shape, "dU", 0);
    g.av = r.number(shape, "aV", 0), g.bv = r.number(shape, "bV", 0);
    g.cv = r.number(shape, "cV", 0), g.dv = r.number(shape, "dV", 0);
    const std::string range = shape.attribute("pRange").value();
    if (range != "" && range != "normalized" && range != "arcLength")
      r.where.fail(shape, r.road, g.s, "paramPoly3 pRange must be arcLength or normalized, got " + quoted(range));
    g.normalized = range != "arcLength";
  } else {
    r.where.fail(shape ? shape : n, r.road, g.s,
                 kind.empty() ? "geometry without a shape" : "unknown geometry " + quoted(kind));
  }
  // A curve that stops or turns back on itself (a tangent that vanishes or reverses between samples)
  // is not a road's reference line.
  if ((g.kind == OdrGeometryKind::poly3 || g.kind == OdrGeometryKind::param_poly3) && g.length > 0) {
    const double pmax = g.kind == OdrGeometryKind::poly3 ? g.length : g.normalized ? 1.0 : g.length;
    Eigen::Vector2d prev = Eigen::Vector2d::Zero();
    for (int k = 0; k <= kFoldSamples; ++k) {
      const double p = pmax * k / kFoldSamples;
      const Eigen::Vector2d t =
          g.kind == OdrGeometryKind::poly3
              ? Eigen::Vector2d(1, g.b + p * (2 * g.c + 3 * g.d * p))
              : Eigen::Vector2d(g.bu + p * (2 * g.cu + 3 * g.du * p), g.bv + p * (2 * g.cv + 3 * g.dv * p));
      const double s = g.s + g.length * k / kFoldSamples;
      if (t.norm() < 1e-9 * std::max(1.0, g.length) || !t.allFinite())
        r.where.fail(shape, r.road, s, kind + " stops (its tangent vanishes)");
      if (k > 0 && t.dot(prev) <= 0) r.where.fail(shape, r.road, s, kind + " folds back on itself");
      prev = t;
    }
  }
  return g;
}

OdrRoadMark read_mark(const Reader& r, const pugi::xml_node& n) {
  OdrRoadMark m;
  m.s_offset = r.required(n, "sOffset");
  m.type = n.attribute("type").value();
  m.weight = n.attribute("weight").value();
  m.color = n.attribute("color").value();
  m.lane_change = n.attribute("laneChange").value();
  if (!m.lane_change.empty() && m.lane_change != "increase" && m.lane_change != "decrease" && m.lane_change != "both" &&
      m.lane_change != "none")
    r.where.fail(n, r.road, std::nullopt,
                 "roadMark laneChange " + quoted(m.lane_change) + " is not increase, decrease, both or none");
  m.width = r.maybe(n, "width");
  if (m.width && (*m.width < 0 || *m.width > 5))
    r.where.fail(n, r.road, std::nullopt, "roadMark width " + std::to_string(*m.width) + " m is not 0 to 5 m");
  for (const auto& line : n.child("type").children("line")) {
    OdrMarkLine l;
    l.length = r.number(line, "length", 0);
    l.space = r.number(line, "space", 0);
    l.t_offset = r.number(line, "tOffset", 0);
    l.s_offset = r.number(line, "sOffset", 0);
    l.width = r.number(line, "width", m.width.value_or(0));
    if (l.length < 0 || l.space < 0 || l.width < 0 || l.width > 5)
      r.where.fail(line, r.road, std::nullopt,
                   "roadMark line with a negative length or space, or a width beyond 0 to 5 m");
    m.lines.push_back(l);
  }
  return m;
}

OdrLane read_lane(const Reader& r, const pugi::xml_node& n, double section_s) {
  OdrLane lane;
  lane.id = r.integer(n, "id");
  lane.line = r.where.line(n);
  lane.type = n.attribute("type").value();
  if (lane.type.empty()) lane.type = "none";
  const std::string level = n.attribute("level").value();
  lane.level = level == "true" || level == "1";
  lane.width = r.cubics(n, "width", "sOffset", 0);
  lane.border = r.cubics(n, "border", "sOffset", 0);
  for (const auto& h : n.children("height"))
    lane.height.push_back({r.required(h, "sOffset"), r.number(h, "inner", 0), r.number(h, "outer", 0)});
  std::stable_sort(lane.height.begin(), lane.height.end(),
                   [](const OdrLaneHeight& a, const OdrLaneHeight& b) { return a.s_offset < b.s_offset; });
  for (const auto& h : lane.height)
    if (std::abs(h.inner) > 100 || std::abs(h.outer) > 100)
      r.where.fail(n, r.road, section_s + h.s_offset, "lane " + std::to_string(lane.id) + " height beyond 100 m");
  for (const auto& m : n.children("roadMark")) lane.marks.push_back(read_mark(r, m));
  std::stable_sort(lane.marks.begin(), lane.marks.end(),
                   [](const OdrRoadMark& a, const OdrRoadMark& b) { return a.s_offset < b.s_offset; });
  if (const auto p = n.child("link").child("predecessor")) lane.predecessor = r.integer(p, "id");
  if (const auto p = n.child("link").child("successor")) lane.successor = r.integer(p, "id");
  return lane;
}

OdrLaneSection read_section(const Reader& r, const pugi::xml_node& n, double road_length) {
  OdrLaneSection sec;
  sec.s = r.required(n, "s");
  if (sec.s < -1e-6 || sec.s > road_length + 1e-3)
    r.where.fail(n, r.road, sec.s, "laneSection outside the road (length " + std::to_string(road_length) + ")");
  for (const char* side : {"left", "right"}) {
    auto& lanes = std::string(side) == "left" ? sec.left : sec.right;
    for (const auto& l : n.child(side).children("lane")) {
      OdrLane lane = read_lane(r, l, sec.s);
      if ((side[0] == 'l') != (lane.id > 0))
        r.where.fail(l, r.road, sec.s, "lane " + std::to_string(lane.id) + " on the " + side + " side");
      lanes.push_back(std::move(lane));
    }
    std::sort(lanes.begin(), lanes.end(),
              [](const OdrLane& a, const OdrLane& b) { return std::abs(a.id) < std::abs(b.id); });
    for (size_t i = 0; i < lanes.size(); ++i)
      if (std::abs(lanes[i].id) != int(i) + 1)
        r.where.fail(n, r.road, sec.s,
                     std::string("the ") + side + " lanes are not numbered 1, 2, ... outwards (lane " +
                         std::to_string(lanes[i].id) + ")");
  }
  if (const auto c = n.child("center").child("lane")) sec.center = read_lane(r, c, sec.s);
  return sec;
}

OdrObject read_object(const Reader& r, const pugi::xml_node& n) {
  OdrObject o;
  o.id = n.attribute("id").value();
  o.type = n.attribute("type").value();
  o.name = n.attribute("name").value();
  o.line = r.where.line(n);
  o.s = r.required(n, "s");
  o.t = r.number(n, "t", 0);
  o.z_offset = r.number(n, "zOffset", 0);
  o.hdg = r.number(n, "hdg", 0);
  o.length = r.number(n, "length", 0);
  o.width = r.number(n, "width", 0);
  o.radius = r.number(n, "radius", 0);
  o.height = r.number(n, "height", 0);
  if (o.length < 0 || o.width < 0 || o.radius < 0 || o.height < 0 || o.length > 1e4 || o.width > 1e4 ||
      o.radius > 1e4 || o.height > 1e3 || std::abs(o.t) > 1e4 || std::abs(o.z_offset) > 1e3)
    r.where.fail(n, r.road, o.s, "object " + quoted(o.id) + " has a negative or huge size");
  // OpenDRIVE 1.4 has one `outline` per object, 1.5 on an `outlines` list of them.
  std::vector<pugi::xml_node> outlines;
  for (const auto& ol : n.children("outline")) outlines.push_back(ol);
  for (const auto& ol : n.child("outlines").children("outline")) outlines.push_back(ol);
  for (const auto& ol : outlines) {
    std::vector<OdrCorner> corners;
    for (const auto& c : ol.children()) {
      const std::string kind = c.name();
      if (kind == "cornerRoad")
        corners.push_back(
            {r.required(c, "s"), r.required(c, "t"), r.number(c, "dz", 0), r.number(c, "height", 0), true});
      else if (kind == "cornerLocal")
        corners.push_back(
            {r.required(c, "u"), r.required(c, "v"), r.number(c, "z", 0), r.number(c, "height", 0), false});
    }
    for (const auto& c : corners)
      if (std::abs(c.u) > 1e4 || std::abs(c.v) > 1e4 || std::abs(c.z) > 1e3 || std::abs(c.height) > 1e3)
        r.where.fail(ol, r.road, o.s, "object " + quoted(o.id) + " has an outline corner beyond 10 km");
    if (!corners.empty()) o.outlines.push_back(std::move(corners));
  }
  return o;
}

// An object with `repeat` records (street lights every 30 m, delineators, bollards): one copy every
// `distance` metres over `length`, its t, size and height moved linearly from each Start to each End
// value, as the standard has it. A repeat of distance 0 is one continuous object (a railing, a wall):
// not built, so the object stays one and says so in its type; the builder names it.
void read_object_and_repeats(const Reader& r, const pugi::xml_node& n, std::vector<OdrObject>& out) {
  const OdrObject o = read_object(r, n);
  bool repeated = false;
  for (const auto& rep : n.children("repeat")) {
    repeated = true;
    const double s0 = r.required(rep, "s"), length = r.required(rep, "length"), distance = r.required(rep, "distance");
    if (length < 0 || distance < 0 || length > kMaxRepeatLength)
      r.where.fail(rep, r.road, s0, "object " + quoted(o.id) + " repeats over a negative or huge length");
    if (distance == 0) {
      OdrObject c = o;
      c.s = s0;
      c.type = "continuous " + (o.type.empty() ? std::string("object") : o.type);
      out.push_back(std::move(c));
      continue;
    }
    if (length / distance > kMaxRepeatCopies)
      r.where.fail(rep, r.road, s0,
                   "object " + quoted(o.id) + " repeats more than " + std::to_string(kMaxRepeatCopies) + " times");
    // Each attribute from its Start to its End value; the object's own where the record gives none.
    auto ramp = [&](const char* start, const char* end, double own, double f) {
      const double a = r.number(rep, start, own), b = r.number(rep, end, a);
      return a + f * (b - a);
    };
    for (int k = 0; k * distance <= length + 1e-9; ++k) {
      const double f = length > 0 ? k * distance / length : 0.0;
      OdrObject c = o;
      c.s = s0 + k * distance;
      c.t = ramp("tStart", "tEnd", o.t, f);
      c.z_offset = ramp("zOffsetStart", "zOffsetEnd", o.z_offset, f);
      c.width = ramp("widthStart", "widthEnd", o.width, f);
      c.length = ramp("lengthStart", "lengthEnd", o.length, f);
      c.height = ramp("heightStart", "heightEnd", o.height, f);
      c.radius = ramp("radiusStart", "radiusEnd", o.radius, f);
      for (auto& outline : c.outlines)
        for (auto& corner : outline)
          if (corner.road_frame) corner.u += c.s - o.s;  // cornerRoad's s moves with the copy
      out.push_back(std::move(c));
    }
  }
  if (!repeated) out.push_back(o);
}

std::optional<OdrLink> read_link(const pugi::xml_node& n) {
  if (!n) return std::nullopt;
  return OdrLink{n.attribute("elementType").value(), n.attribute("elementId").value(),
                 n.attribute("contactPoint").value()};
}

OdrRoad read_road(const Where& where, const pugi::xml_node& n, double max_extent) {
  OdrRoad road;
  road.id = n.attribute("id").value();
  road.name = n.attribute("name").value();
  road.line = where.line(n);
  if (road.id.empty()) where.fail(n, "", std::nullopt, "road without an id");
  Reader r{where, road.id};
  road.length = r.required(n, "length");
  if (!(road.length > 0) || road.length > max_extent)
    where.fail(
        n, road.id, std::nullopt,
        "length " + std::to_string(road.length) + " m is not above 0 and below " + std::to_string(max_extent) + " m");
  const std::string junction = n.attribute("junction").value();
  road.junction = junction.empty() ? "-1" : junction;
  const std::string rule = n.attribute("rule").value();
  if (rule != "" && rule != "RHT" && rule != "LHT")
    where.fail(n, road.id, std::nullopt, "rule " + quoted(rule) + " is neither RHT nor LHT");
  road.left_hand_traffic = rule == "LHT";
  road.predecessor = read_link(n.child("link").child("predecessor"));
  road.successor = read_link(n.child("link").child("successor"));
  if (const auto t = n.child("type")) road.type = t.attribute("type").value();
  for (const auto& g : n.child("planView").children("geometry")) {
    road.plan_view.push_back(read_geometry(r, g));
    const OdrGeometry& geo = road.plan_view.back();
    if (std::hypot(geo.x, geo.y) > max_extent)
      where.fail(g, road.id, geo.s,
                 "geometry starts " + std::to_string(std::hypot(geo.x, geo.y)) + " m from the map's origin, beyond " +
                     std::to_string(max_extent) + " m");
    if (road.plan_view.size() > 1 && geo.s < road.plan_view[road.plan_view.size() - 2].s - 1e-6)
      where.fail(g, road.id, geo.s, "geometries out of order of s");
  }
  if (road.plan_view.empty()) where.fail(n, road.id, std::nullopt, "no planView geometry");
  road.elevation = r.cubics(n.child("elevationProfile"), "elevation", "s", 0);
  road.superelevation = r.cubics(n.child("lateralProfile"), "superelevation", "s", 0);
  for (const auto& c : road.superelevation)
    if (std::abs(c.a) > 1.0)
      where.fail(n.child("lateralProfile"), road.id, c.s, "superelevation beyond 1 rad (57 degrees)");
  road.lane_offset = r.cubics(n.child("lanes"), "laneOffset", "s", 0);
  for (const auto& s : n.child("lanes").children("laneSection"))
    road.sections.push_back(read_section(r, s, road.length));
  std::stable_sort(road.sections.begin(), road.sections.end(),
                   [](const OdrLaneSection& a, const OdrLaneSection& b) { return a.s < b.s; });
  if (road.sections.empty()) where.fail(n, road.id, std::nullopt, "no laneSection");
  // A width polynomial that goes negative within its range makes lanes overlap: the file is wrong.
  // A millimetre is allowed for rounding (editors end merging lanes at -1e-16 and the like).
  for (size_t i = 0; i < road.sections.size(); ++i) {
    const OdrLaneSection& sec = road.sections[i];
    const double length = road.section_end(i) - sec.s;
    for (const auto* side : {&sec.left, &sec.right})
      for (const auto& lane : *side)
        for (size_t k = 0; k < lane.width.size(); ++k) {
          const double s0 = std::max(0.0, lane.width[k].s);
          const double s1 = k + 1 < lane.width.size() ? lane.width[k + 1].s : length;
          if (s1 <= s0) continue;
          if (cubic_min(lane.width[k], s0, s1) < -1e-3) {
            // Where it goes negative, for the message: the first negative sample, then bisection.
            const OdrCubic& w = lane.width[k];
            double lo = s0, hi = s1;
            for (int j = 1; j <= 64; ++j)
              if (w.at(s0 + (s1 - s0) * j / 64) < -1e-3) {
                hi = s0 + (s1 - s0) * j / 64, lo = s0 + (s1 - s0) * (j - 1) / 64;
                break;
              }
            if (w.at(lo) < 0) hi = lo;
            for (int it = 0; it < 60 && hi - lo > 1e-9; ++it) (w.at(0.5 * (lo + hi)) < 0 ? hi : lo) = 0.5 * (lo + hi);
            const double at = hi;
            where.fail_at(where.at_line(lane.line), road.id, sec.s + at,
                          "lane " + std::to_string(lane.id) + " width goes negative");
          }
        }
  }
  // Values a road cannot have (a fuzzed or corrupt file): they would overflow the world's integer
  // geometry further on.
  auto bounded = [&](const std::vector<OdrCubic>& records, double base, double end, double limit, const char* what) {
    for (size_t k = 0; k < records.size(); ++k) {
      const double s0 = std::max(base, records[k].s), s1 = k + 1 < records.size() ? records[k + 1].s : end;
      for (int j = 0; j <= kFoldSamples && s1 >= s0; ++j) {
        const double s = s0 + (s1 - s0) * j / kFoldSamples;
        if (!(std::abs(records[k].at(s)) <= limit))
          where.fail(n, road.id, s, std::string(what) + " beyond " + std::to_string(int(limit)) + " m");
      }
    }
  };
  bounded(road.elevation, 0, road.length, max_extent, "elevation");
  bounded(road.lane_offset, 0, road.length, kMaxWidth, "laneOffset");
  for (size_t i = 0; i < road.sections.size(); ++i)
    for (const auto* side : {&road.sections[i].left, &road.sections[i].right})
      for (const auto& lane : *side) {
        const double length = road.section_end(i) - road.sections[i].s;
        bounded(lane.width, 0, length, kMaxWidth, "lane width");
        bounded(lane.border, 0, length, kMaxWidth, "lane border");
      }
  for (const auto& g : road.plan_view) {
    const OdrPose end = geometry_pose(g, g.length);
    if (!(std::hypot(end.x, end.y) <= max_extent) || !std::isfinite(end.hdg))
      where.fail(n, road.id, g.s + g.length, "geometry ends beyond " + std::to_string(int(max_extent)) + " m");
  }
  for (const auto& o : n.child("objects").children("object")) read_object_and_repeats(r, o, road.objects);
  for (const auto& s : n.child("signals").children()) road.signals += std::string(s.name()) == "signal";
  return road;
}

OdrJunction read_junction(const Where& where, const pugi::xml_node& n) {
  OdrJunction j;
  j.id = n.attribute("id").value();
  j.name = n.attribute("name").value();
  Reader r{where, ""};
  for (const auto& c : n.children("connection")) {
    OdrConnection con;
    con.id = c.attribute("id").value();
    con.incoming_road = c.attribute("incomingRoad").value();
    con.connecting_road = c.attribute("connectingRoad").value();
    con.contact_point = c.attribute("contactPoint").value();
    for (const auto& l : c.children("laneLink")) con.lane_links.push_back({r.integer(l, "from"), r.integer(l, "to")});
    j.connections.push_back(std::move(con));
  }
  return j;
}

// "+lat_0=49 +lon_0=8": the value of one +key=value token, if there.
std::optional<double> proj_value(const std::string& proj, const std::string& key) {
  std::istringstream in(proj);
  std::string token;
  while (in >> token)
    if (token.rfind("+" + key + "=", 0) == 0) return parse_number(token.substr(key.size() + 2));
  return std::nullopt;
}

bool proj_flag(const std::string& proj, const std::string& flag) {
  std::istringstream in(proj);
  std::string token;
  while (in >> token)
    if (token == "+" + flag) return true;
  return false;
}

// The header's <offset>: takes a point of the map's frame to the projection's (rotate by hdg, then add).
struct HeaderOffset {
  double x = 0, y = 0, hdg = 0;
};

// Where the map's (0, 0) is on the earth, from the geoReference's PROJ string and the header's offset;
// or the reason it cannot be said. The map's x / y are then taken as east / north about that point.
std::optional<Geodetic> map_origin(OdrMap& map, const HeaderOffset& off) {
  const std::string& proj = map.geo_reference;
  const auto lat = proj_value(proj, "lat_0"), lon = proj_value(proj, "lon_0");
  if (proj.find("+proj=utm") != std::string::npos) {
    const auto zone = proj_value(proj, "zone");
    // The zone's false easting is 500 km: a map at easting 0 has no offset (a placeholder).
    if (!zone || *zone < 1 || *zone > 60 || std::floor(*zone) != *zone || !(off.x > 0 && off.x < 1e6) ||
        !(std::abs(off.y) < 1e7))
      return std::nullopt;
    double lat_deg = 0, lon_deg = 0;
    try {
      GeographicLib::UTMUPS::Reverse(int(*zone), !proj_flag(proj, "south"), off.x, off.y, lat_deg, lon_deg);
    } catch (const GeographicLib::GeographicErr&) {
      return std::nullopt;  // a northing outside the zone
    }
    double x = 0, y = 0, gamma = 0, k = 0;
    GeographicLib::TransverseMercator::UTM().Forward(6.0 * *zone - 183, lat_deg,  // the zone's central meridian
                                                     lon_deg, x, y, gamma, k);
    std::ostringstream o;
    o.precision(3);
    o << "geoReference " << quoted(proj) << ": the map's x / y are UTM grid metres, taken as east / north at its "
      << "origin; there grid north is " << std::fixed << std::abs(gamma) << " deg from true north, so a point 1 km "
      << "away is placed " << std::abs(gamma) * M_PI / 180 * 1000 << " m off on the earth (its place in the world "
      << "is exact)";
    map.warnings.push_back(o.str());
    return Geodetic{lat_deg, lon_deg, 0};
  }
  const bool usable = lat && lon && std::abs(*lat) <= 85 && std::abs(*lon) <= 180 && (*lat != 0 || *lon != 0);
  if (!usable) return std::nullopt;
  if (proj.find("+proj=") != std::string::npos && proj.find("+proj=tmerc") == std::string::npos)
    map.warnings.push_back("geoReference " + quoted(proj) +
                           " is not a transverse Mercator: its lat_0 / lon_0 taken as the origin of a local one");
  // The map's (0, 0) in metres east and north of the projection's origin.
  const double east = off.x - proj_value(proj, "x_0").value_or(0), north = off.y - proj_value(proj, "y_0").value_or(0);
  if (east == 0 && north == 0) return Geodetic{*lat, *lon, 0};
  if (std::abs(east) > 1e6 || std::abs(north) > 1e6) return std::nullopt;
  const double k0 = proj_value(proj, "k_0").value_or(proj_value(proj, "k").value_or(1.0));
  const GeographicLib::TransverseMercator tm(GeographicLib::Constants::WGS84_a(), GeographicLib::Constants::WGS84_f(),
                                             k0 > 0 ? k0 : 1.0);
  double x0 = 0, y0 = 0, lat_deg = 0, lon_deg = 0;
  tm.Forward(*lon, *lat, *lon, x0, y0);
  tm.Reverse(*lon, east, y0 + north, lat_deg, lon_deg);
  return Geodetic{lat_deg, lon_deg, 0};
}

// The origin from the geoReference, or the reason it is a placeholder.
void read_geo_reference(OdrMap& map, const OdrReadOptions& options, const HeaderOffset& off) {
  if (off.hdg != 0)
    map.warnings.push_back("header offset hdg " + std::to_string(off.hdg) +
                           " rad not applied: the map's x axis is taken as east");
  if (!options.override_origin)
    if (const auto origin = map_origin(map, off)) {
      map.origin = *origin;
      map.origin_from_map = true;
      return;
    }
  map.origin = options.origin.value_or(Geodetic{});
  if (options.override_origin) return;
  std::ostringstream o;
  o << (map.geo_reference.empty() ? std::string("no geoReference")
                                  : "geoReference " + quoted(map.geo_reference) + " is a placeholder")
    << ": the map's x / y are taken about " << (options.origin ? "the world's origin " : "the default origin ")
    << map.origin.lat_deg << ", " << map.origin.lon_deg;
  map.warnings.push_back(o.str());
}

OdrMap parse(const std::string& xml, const std::string& name, const OdrReadOptions& options) {
  const Where where(name, xml);
  pugi::xml_document doc;
  const pugi::xml_parse_result ok = doc.load_buffer(xml.data(), xml.size());
  if (!ok) {
    // pugixml's offset into the text, as a line.
    const size_t at = size_t(std::max<ptrdiff_t>(0, ok.offset));
    const auto line = std::count(xml.begin(), xml.begin() + ptrdiff_t(std::min(at, xml.size())), '\n') + 1;
    throw InputError(name + ":" + std::to_string(line) + ": not XML: " + ok.description());
  }
  const pugi::xml_node root = doc.document_element();
  if (std::string(root.name()) != "OpenDRIVE")
    throw InputError(where.at(root) + ": not an OpenDRIVE file (its root element is " + quoted(root.name()) + ")");
  OdrMap map;
  map.file = name;
  const pugi::xml_node header = root.child("header");
  if (!header) where.fail(root, "", std::nullopt, "OpenDRIVE without a header");
  Reader r{where, ""};
  map.rev_major = r.revision(header, "revMajor", 1);
  map.rev_minor = r.revision(header, "revMinor", 4);
  if (map.rev_major != 1)
    where.fail(header, "", std::nullopt, "OpenDRIVE " + std::to_string(map.rev_major) + ".x is not 1.x");
  if (map.rev_minor < 4 || map.rev_minor > 8)
    map.warnings.push_back("OpenDRIVE 1." + std::to_string(map.rev_minor) + " read as 1.4-1.8");
  const pugi::xml_node geo = header.child("geoReference");
  map.geo_reference = geo.child_value();
  if (map.geo_reference.empty()) map.geo_reference = geo.text().get();
  const pugi::xml_node offset = header.child("offset");
  read_geo_reference(map, options, {r.number(offset, "x", 0), r.number(offset, "y", 0), r.number(offset, "hdg", 0)});

  for (const auto& n : root.children("road")) {
    map.roads.push_back(read_road(where, n, options.max_extent_m));
    if (!map.road_index.emplace(map.roads.back().id, map.roads.size() - 1).second)
      where.fail(n, map.roads.back().id, std::nullopt, "road id used twice");
  }
  if (map.roads.empty()) where.fail(root, "", std::nullopt, "no roads");
  std::map<std::string, const pugi::xml_node> junction_nodes;
  for (const auto& n : root.children("junction")) {
    map.junctions.push_back(read_junction(where, n));
    junction_nodes.emplace(map.junctions.back().id, n);
  }
  // Links: every road or junction named must be there.
  const auto road_nodes = root.children("road");
  auto node_it = road_nodes.begin();
  for (const auto& road : map.roads) {
    const pugi::xml_node n = *node_it++;
    for (const auto* link : {&road.predecessor, &road.successor}) {
      if (!*link) continue;
      const bool to_road = (*link)->element_type == "road";
      const bool found =
          to_road ? map.road((*link)->element_id) != nullptr : junction_nodes.count((*link)->element_id) > 0;
      if (!found)
        where.fail(n.child("link"), road.id, link == &road.predecessor ? 0.0 : road.length,
                   std::string(link == &road.predecessor ? "predecessor" : "successor") + " " +
                       (to_road ? "road " : "junction ") + quoted((*link)->element_id) + " is not in the map");
    }
    if (road.junction != "-1" && !junction_nodes.count(road.junction))
      where.fail(n, road.id, std::nullopt, "junction " + quoted(road.junction) + " is not in the map");
  }
  for (const auto& j : map.junctions)
    for (const auto& c : j.connections)
      for (const auto* id : {&c.incoming_road, &c.connecting_road})
        if (!map.road(*id))
          where.fail(junction_nodes.at(j.id), "", std::nullopt,
                     "junction " + quoted(j.id) + " connection " + quoted(c.id) + ": road " + quoted(*id) +
                         " is not in the map");
  return map;
}

}  // namespace

OdrMap parse_opendrive(const std::string& xml, const std::string& name, const OdrReadOptions& options) {
  return parse(xml, name, options);
}

OdrMap read_opendrive(const std::string& path, const OdrReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the OpenDRIVE map");
  std::ostringstream text;
  text << in.rdbuf();
  return parse(text.str(), path, options);
}

}  // namespace lidarloop
