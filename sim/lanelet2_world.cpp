#include "sim/lanelet2_world.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <unordered_map>

#include "common/input_error.hpp"
#include "common/points_kd_tree.hpp"
#include "sim/actor_assets.hpp"
#include "sim/curb_band.hpp"
#include "sim/import_report.hpp"
#include "sim/mesh_shapes.hpp"
#include "sim/polyline.hpp"
#include "sim/region.hpp"
#include "sim/scattered_heights.hpp"

namespace lidarloop {
namespace {

// Edges (curb lines, the carriageway's boundary) are cut into pieces at most this long, so a KD-tree
// over their midpoints finds the nearest piece among a few candidates.
constexpr double kEdgePiece = 0.5;                        // m
constexpr size_t kEdgeNeighbours = 12;                    // candidates per look-up
constexpr double kOnLine = 1e-4;                          // m: a point this close to a curb line is on its top
constexpr double kRibbonMargin = 0.01;                    // m of curb top and of low ground meshed with the face
constexpr double kSideProbe = 0.25;                       // m each side of a curbstone tested for the carriageway
constexpr double kOnEdge = 0.3;                           // m: a road border this near the carriageway's edge is it
constexpr double kJoin = 0.01;                            // m: line ends closer than this are joined
constexpr double kRoadTile = 0.5;                         // m: pavement squares (crown, roughness)
constexpr double kPavedTile = 0.5, kPavedSquare = 1.0;    // m: sidewalks, islands, parking
constexpr double kGroundTile = 2.0, kGroundSquare = 8.0;  // m: grass and the rest, smooth
constexpr double kRoofTile = 4.0;                         // m: roofs are flat
constexpr double kFoundation = 0.3;                       // m: walls and buildings reach this far into the ground
constexpr double kAisle = 6.0;          // m between facing rows of perpendicular stalls (EAR 05: 6.00 m for 90 degrees)
constexpr double kPoleClearance = 0.5;  // m: a pole over the carriageway moves this far behind its edge
constexpr double kMaxArm = 8.0;         // m: farther from the edge, a pole stands where the map says
constexpr float kPoleRadius = 0.08f, kPoleTopRadius = 0.06f;  // as build_world's poles
constexpr float kPlateThickness = 0.05f;                      // m

Eigen::Vector2d left_normal(const Eigen::Vector2d& t) { return {-t.y(), t.x()}; }

Polyline2d flat(const std::vector<Eigen::Vector3d>& points) {
  Polyline2d out;
  for (const auto& p : points)
    if (out.empty() || (p.head<2>() - out.back()).norm() > 1e-6) out.push_back(p.head<2>());
  return out;
}

std::string tag(const Lanelet2Tags& tags, const std::string& key) {
  const auto it = tags.find(key);
  return it == tags.end() ? std::string() : it->second;
}

std::optional<double> number_tag(const Lanelet2Tags& tags, const std::string& key) {
  const std::string v = tag(tags, key);
  if (v.empty()) return std::nullopt;
  try {
    size_t used = 0;
    const double x = std::stod(v, &used);
    if (used > 0 && std::isfinite(x)) return x;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

// A region from closed rings (outer filled, inner as holes), whatever their orientation.
region::Paths area_region(const std::vector<std::vector<Eigen::Vector3d>>& outer,
                          const std::vector<std::vector<Eigen::Vector3d>>& inner) {
  region::Paths out, holes;
  for (const auto& ring : outer)
    if (ring.size() >= 3) out = region::unite(out, {region::to_path(flat(ring))});
  for (const auto& ring : inner)
    if (ring.size() >= 3) holes = region::unite(holes, {region::to_path(flat(ring))});
  return holes.empty() ? out : region::subtract(out, holes);
}

// ---------------------------------------------------------------------------------------------------
// Line pieces with a KD-tree over their midpoints.

struct Segment {
  Eigen::Vector2d a, b;
  int group = 0;        // pieces of one line (a way, a run of the carriageway's edge) share it
  double value = 0;     // height of the raised side above the low one, m
  int high = 0;         // the raised side: +1 left of a -> b, -1 right, 0 neither
  bool a_free = false;  // an end of its line that meets no other line's end
  bool b_free = false;
};

struct Candidate {
  size_t index;
  double distance;  // to the piece
  double t;         // where the foot of p falls along a -> b (0..1 on the piece)
  double perp;      // signed distance to the piece's line, left positive
};

Candidate measure(const Segment& s, size_t index, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = s.b - s.a, ap = p - s.a;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0 ? ap.dot(d) / l2 : 0.0;
  const double tc = std::clamp(t, 0.0, 1.0);
  const double perp = l2 > 0 ? (d.x() * ap.y() - d.y() * ap.x()) / std::sqrt(l2) : 0.0;
  return {index, (ap - d * tc).norm(), t, perp};
}

class SegmentIndex {
 public:
  // Cuts each segment into pieces of at most kEdgePiece (only the first and last keep the free ends).
  explicit SegmentIndex(const std::vector<Segment>& segments) {
    for (const Segment& s : segments) {
      const double length = (s.b - s.a).norm();
      if (length < 1e-9) continue;
      const int n = std::max(1, int(std::ceil(length / kEdgePiece)));
      for (int k = 0; k < n; ++k) {
        Segment piece = s;
        piece.a = s.a + (s.b - s.a) * (double(k) / n);
        piece.b = s.a + (s.b - s.a) * (double(k + 1) / n);
        piece.a_free = s.a_free && k == 0;
        piece.b_free = s.b_free && k == n - 1;
        pieces_.push_back(piece);
        mids_.push_back(0.5 * (piece.a + piece.b));
      }
    }
    if (!mids_.empty()) tree_ = std::make_unique<PointsKdTree>(&mids_);
  }
  SegmentIndex(const SegmentIndex&) = delete;
  SegmentIndex& operator=(const SegmentIndex&) = delete;

  bool empty() const { return pieces_.empty(); }
  const Segment& operator[](size_t i) const { return pieces_[i]; }

  // Up to kEdgeNeighbours pieces nearest p, and a radius beyond which every piece not among them lies
  // (infinite when they are all of them).
  size_t candidates(const Eigen::Vector2d& p, std::array<Candidate, kEdgeNeighbours>& out, double& radius) const {
    std::array<uint32_t, kEdgeNeighbours> idx{};
    std::array<double, kEdgeNeighbours> d2{};
    if (!tree_) return 0;
    const size_t found = tree_->tree.knnSearch(p.data(), kEdgeNeighbours, idx.data(), d2.data());
    for (size_t k = 0; k < found; ++k) out[k] = measure(pieces_[idx[k]], idx[k], p);
    radius = found < kEdgeNeighbours || found == pieces_.size() ? std::numeric_limits<double>::infinity()
                                                                : std::sqrt(d2[found - 1]) - kEdgePiece / 2;
    return found;
  }

  // The nearest piece. Where p is nearest a corner two pieces share, the one whose line lies farther
  // from p tells the side p is on (the usual rule for signed distances to polygons).
  std::optional<Candidate> nearest(const Eigen::Vector2d& p) const {
    std::array<Candidate, kEdgeNeighbours> c{};
    double radius = 0;
    const size_t n = candidates(p, c, radius);
    if (n == 0) return std::nullopt;
    Candidate best = c[0];
    for (size_t k = 1; k < n; ++k) {
      const double dd = c[k].distance - best.distance;
      if (dd < -1e-9 || (std::abs(dd) <= 1e-9 && std::abs(c[k].perp) > std::abs(best.perp))) best = c[k];
    }
    return best;
  }

 private:
  std::vector<Segment> pieces_;
  std::vector<Eigen::Vector2d> mids_;
  std::unique_ptr<PointsKdTree> tree_;
};

// The carriageway's boundary (Clipper rings: the filled side is on the left of every ring, outer or
// hole): fast inside tests and distances to the edge.
class EdgeField {
 public:
  explicit EdgeField(const region::Paths& area) : index_(segments(area)) {}
  bool inside(const Eigen::Vector2d& p) const {
    const auto c = index_.nearest(p);
    return c && c->perp > 0;
  }
  double distance(const Eigen::Vector2d& p) const {
    const auto c = index_.nearest(p);
    return c ? c->distance : std::numeric_limits<double>::infinity();
  }
  // The nearest point of the edge and the unit normal out of the area there.
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> nearest_outside(const Eigen::Vector2d& p) const {
    const auto c = index_.nearest(p);
    if (!c) return std::nullopt;
    const Segment& s = index_[c->index];
    const Eigen::Vector2d d = s.b - s.a;
    const Eigen::Vector2d foot = s.a + d * std::clamp(c->t, 0.0, 1.0);
    return std::make_pair(foot, Eigen::Vector2d(-left_normal(d.normalized())));
  }

 private:
  static std::vector<Segment> segments(const region::Paths& area) {
    std::vector<Segment> out;
    for (const auto& path : area) {
      const Polyline2d ring = region::to_polyline(path, true);
      for (size_t i = 1; i < ring.size(); ++i) out.push_back({ring[i - 1], ring[i]});
    }
    return out;
  }
  SegmentIndex index_;
};

// The raised ground's height above the terrain: each curb line gives its reveal on its raised side
// and 0 on the other (half-way round a free end of the line, smoothly), road borders and curbless
// edges of the carriageway give 0; lines are blended by modified Shepard weights of their distance,
// so the ground has no step away from the curbs and reaches each curb's top right behind it.
class RaisedEdges {
 public:
  explicit RaisedEdges(const std::vector<Segment>& segments) : index_(segments) {}
  double operator()(const Eigen::Vector2d& p) const {
    std::array<Candidate, kEdgeNeighbours> c{};
    double radius = 0;
    const size_t n = index_.candidates(p, c, radius);
    if (n == 0) return 0;
    struct Line {
      int group;
      double distance, perp, value;
    };
    std::array<Line, kEdgeNeighbours> lines{};
    size_t count = 0;
    for (size_t k = 0; k < n; ++k) {
      const Segment& s = index_[c[k].index];
      double value = s.value;
      if (s.high != 0 && c[k].distance >= kOnLine) {
        const double side = s.high * c[k].perp;  // positive on the raised side
        const bool round_end = (c[k].t < 0 && s.a_free) || (c[k].t > 1 && s.b_free);
        value *= round_end ? 0.5 + 0.5 * side / c[k].distance : (side >= 0 ? 1.0 : 0.0);
      }
      size_t j = 0;
      while (j < count && lines[j].group != s.group) ++j;
      if (j == count) {
        lines[count++] = {s.group, c[k].distance, c[k].perp, value};
        continue;
      }
      const double dd = c[k].distance - lines[j].distance;
      if (dd < -1e-9 || (std::abs(dd) <= 1e-9 && std::abs(c[k].perp) > std::abs(lines[j].perp)))
        lines[j] = {s.group, c[k].distance, c[k].perp, value};
    }
    const Line* nearest = &lines[0];
    for (size_t j = 1; j < count; ++j)
      if (lines[j].distance < nearest->distance) nearest = &lines[j];
    if (nearest->distance < kOnLine) return nearest->value;
    double sw = 0, swv = 0;
    for (size_t j = 0; j < count; ++j) {
      const double d = lines[j].distance;
      const double w = std::isinf(radius) ? 1 / (d * d) : std::pow(std::max(0.0, radius - d) / (radius * d), 2);
      sw += w;
      swv += w * lines[j].value;
    }
    return sw > 0 ? swv / sw : nearest->value;
  }

 private:
  SegmentIndex index_;
};

// Marks the ends of lines that meet no other line's end (within kJoin) as free.
void mark_free_ends(std::vector<Segment>& segments) {
  auto key = [](const Eigen::Vector2d& p) {
    return std::make_pair(int64_t(std::floor(p.x() / kJoin)), int64_t(std::floor(p.y() / kJoin)));
  };
  // Only curb lines (raised on one side) join: where a curb runs on as a road border, its end is free.
  std::map<std::pair<int64_t, int64_t>, std::vector<std::pair<Eigen::Vector2d, int>>> ends;
  for (const Segment& s : segments) {
    if (s.high == 0) continue;
    ends[key(s.a)].emplace_back(s.a, s.group);
    ends[key(s.b)].emplace_back(s.b, s.group);
  }
  auto joined = [&](const Eigen::Vector2d& p, int group, int own_count) {
    const auto [i, j] = key(p);
    int same = 0;
    for (int64_t di = -1; di <= 1; ++di)
      for (int64_t dj = -1; dj <= 1; ++dj) {
        const auto it = ends.find({i + di, j + dj});
        if (it == ends.end()) continue;
        for (const auto& [q, g] : it->second)
          if ((q - p).norm() <= kJoin) {
            if (g != group) return true;
            ++same;
          }
      }
    return same > own_count;  // a closed line meets its own other end
  };
  for (Segment& s : segments) {
    // Within a line consecutive pieces share their ends: an end met only by its own neighbour piece
    // (2 hits: itself and the neighbour) is interior; the line's ends are hit once, or twice if closed.
    s.a_free = s.a_free && !joined(s.a, s.group, 1);
    s.b_free = s.b_free && !joined(s.b, s.group, 1);
  }
}

// The minimum-area rectangle round the points over the directions of the ring's edges: its long axis
// (unit), and the extents along it and across.
struct Frame {
  Eigen::Vector2d u{1, 0}, v{0, 1};
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};
Frame long_axis_frame(const Polyline2d& ring) {
  Frame best;
  double best_area = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d d = ring[(i + 1) % ring.size()] - ring[i];
    if (d.norm() < 1e-6) continue;
    Frame f;
    f.u = d.normalized();
    f.v = left_normal(f.u);
    f.u0 = f.v0 = std::numeric_limits<double>::infinity();
    f.u1 = f.v1 = -std::numeric_limits<double>::infinity();
    for (const auto& p : ring) {
      f.u0 = std::min(f.u0, p.dot(f.u)), f.u1 = std::max(f.u1, p.dot(f.u));
      f.v0 = std::min(f.v0, p.dot(f.v)), f.v1 = std::max(f.v1, p.dot(f.v));
    }
    const double area = (f.u1 - f.u0) * (f.v1 - f.v0);
    if (area < best_area - 1e-9) best_area = area, best = f;
  }
  if (best.u1 - best.u0 < best.v1 - best.v0) {  // make u the long side
    Frame f = best;
    best.u = f.v, best.v = -f.u;
    best.u0 = f.v0, best.u1 = f.v1, best.v0 = -f.u1, best.v1 = -f.u0;
  }
  return best;
}

bool is_motor(const std::string& subtype) {
  // Lanelet2 LaneletAndAreaTagging.md: a lanelet without a subtype is a road.
  return subtype.empty() || subtype == "road" || subtype == "highway" || subtype == "play_street" ||
         subtype == "bus_lane" || subtype == "emergency_lane";
}

struct Builder {
  Builder(const Lanelet2Map& m, const Lanelet2WorldParams& p, const MaterialTable& mt, const std::string& actors,
          Lanelet2BuildReport& r)
      : map(m), params(p), materials(mt), actors_dir(actors), report(r) {}
  const Lanelet2Map& map;
  const Lanelet2WorldParams& params;
  const MaterialTable& materials;
  const std::string& actors_dir;
  Lanelet2BuildReport& report;
  Lanelet2Standards std_;
  World world;
  MarkingPainter painter{params.paint, materials};  // each marking's wear (uniform without params.paint)
  region::Paths motor;                              // road lanelets alone, without bicycle lanes
  std::shared_ptr<const EdgeField> edges;
  std::shared_ptr<const RaisedEdges> raised;
  std::function<double(const Eigen::Vector2d&)> terrain;
  std::vector<const Lanelet2LineString*> curbstones;
  std::vector<std::vector<int>> curb_high_side;  // per curbstone, per segment: +1 left, -1 right
  std::vector<double> curb_height;
  std::vector<CurbProfile> curb_profile;

  MaterialId mat(const std::string& name) const { return materials.id(name, map.file); }
  double ground(const Eigen::Vector2d& p) const {
    return edges->inside(p) ? world.surface->carriageway(p) : double(world.raised_level(p));
  }

  void standards() {
    report.country = !params.country.empty() ? params.country : !map.country.empty() ? map.country : "de";
    std_ = lanelet2_standards(report.country);
    if (params.curb_high) std_.curb_high = *params.curb_high;
    if (params.curb_low) std_.curb_low = *params.curb_low;
    if (params.cross_slope) std_.cross_slope = *params.cross_slope;
  }

  // The carriageway: road lanelets and the bicycle lanes on the road (a bicycle lane whose curbstone
  // bound is shared with a road lanelet lies behind that curb: a cycle track, paved at the raised level).
  region::Paths cycle_tracks;
  void carriageway() {
    std::set<Lanelet2Id> motor_bounds;
    for (const auto& l : map.lanelets)
      if (is_motor(l.subtype)) motor_bounds.insert({l.left, l.right});
    auto is_curb = [&](Lanelet2Id id) {
      const Lanelet2LineString* s = map.line(id);
      return s && s->type == "curbstone";
    };
    region::Paths road;
    for (const auto& l : map.lanelets) {
      Polyline2d poly = flat(l.left_points);
      const Polyline2d right = flat(l.right_points);
      poly.insert(poly.end(), right.rbegin(), right.rend());
      if (poly.size() < 3) continue;
      const region::Paths piece = region::unite({region::to_path(poly)}, {});
      if (is_motor(l.subtype)) {
        motor = region::unite(motor, piece);
        road = region::unite(road, piece);
        ++report.road_lanelets;
      } else if (l.subtype == "bicycle_lane") {
        const bool behind_curb =
            (is_curb(l.left) && motor_bounds.count(l.left)) || (is_curb(l.right) && motor_bounds.count(l.right));
        if (behind_curb) {
          cycle_tracks = region::unite(cycle_tracks, piece);
          ++report.cycle_tracks;
        } else {
          road = region::unite(road, piece);
          ++report.road_lanelets;
        }
      } else {
        ++report.not_built[(l.subtype.empty() ? std::string("untyped") : l.subtype) + " lanelet"];
      }
    }
    world.carriageway = region::closing(road, params.sliver_radius);
    if (world.carriageway.empty()) throw InputError(map.file + ": no road lanelets: the world has no carriageway");
    cycle_tracks = region::subtract(cycle_tracks, world.carriageway);
    edges = std::make_shared<const EdgeField>(world.carriageway);
  }

  // Terrain from the points' `ele` (ground lines only: lights and signs hang above it), and the crown.
  void surface() {
    std::vector<Eigen::Vector2d> pts;
    std::vector<double> zs;
    size_t bound_points = 0, bound_with_z = 0;
    for (const auto& l : map.lanelets)
      for (const auto* side : {&l.left_points, &l.right_points})
        for (const auto& p : *side) {
          pts.push_back(p.head<2>()), zs.push_back(p.z());
          ++bound_points;
          bound_with_z += p.z() != 0;
        }
    for (const auto& [id, s] : map.lines)
      if (s.type == "curbstone" || s.type == "road_border")
        for (const auto& p : s.points) pts.push_back(p.head<2>()), zs.push_back(p.z());
    // A map whose bounds mostly carry heights was surveyed in 3-D (its cross-fall is in them too). A
    // few heights among points without (Karlsruhe's 4 nodes at `ele` 3 among 2,258) are not a terrain:
    // the reader gives 0 where `ele` is absent, so blending them would raise 3 m hills round them.
    const bool surveyed = bound_points > 0 && 2 * bound_with_z >= bound_points;
    const size_t with_z = size_t(std::count_if(zs.begin(), zs.end(), [](double z) { return z != 0; }));
    if (with_z > 0 && !surveyed)
      report.warnings.push_back(std::to_string(with_z) + " of " + std::to_string(zs.size()) +
                                " ground points carry a height, most do not: heights ignored, the ground is level");
    if (surveyed) {
      auto heights = std::make_shared<const ScatteredHeights>(pts, zs);
      terrain = [heights](const Eigen::Vector2d& p) { return (*heights)(p); };
    } else {
      terrain = [](const Eigen::Vector2d&) { return 0.0; };
    }
    const double slope = surveyed ? 0.0 : std_.cross_slope, reach = std_.crown_distance;
    std::ostringstream why;
    if (surveyed)
      why << "from the map's ele";
    else
      why << slope * 100 << " % up to " << reach << " m from the edge ("
          << (report.country == "us" ? "TxDOT Roadway Design Manual" : "RAS-Q 96 / RASt 06") << ")";
    report.cross_fall = why.str();
    auto e = edges;
    auto crown = [e, slope, reach](const Eigen::Vector2d& p) {
      return slope == 0 || !e->inside(p) ? 0.0 : slope * std::min(e->distance(p), reach);
    };
    world.surface = std::make_shared<const RoadSurface>(terrain, crown, params.geometry);
  }

  // Curbstones: which side is raised, per segment; the raised ground from them.
  void curbs() {
    std::vector<Segment> raised_segments, border_segments;
    std::vector<Lanelet2Id> unclear_curbs;
    int group = 0;
    for (const auto& [id, s] : map.lines) {
      if (s.type != "curbstone" && s.type != "road_border") continue;
      const Polyline2d line = flat(s.points);
      if (line.size() < 2) continue;
      for (size_t i = 1; i < line.size(); ++i) border_segments.push_back({line[i - 1], line[i]});
      if (s.type == "road_border") continue;
      const bool low = s.subtype == "low";
      curbstones.push_back(&s);
      curb_height.push_back(low ? std_.curb_low : std_.curb_high);
      curb_profile.push_back(low ? std_.low_profile : CurbProfile::vertical);
      (low ? report.curbstones_low : report.curbstones_high)++;
      report.curb_length_m += polyline_length(line);
      world.curbs.push_back(line);
      world.curb_kinds.push_back(curb_profile_name(curb_profile.back()));
      std::vector<int> sides;
      int unclear = 0;
      for (size_t i = 1; i < line.size(); ++i) {
        const Eigen::Vector2d m = 0.5 * (line[i - 1] + line[i]);
        const Eigen::Vector2d n = left_normal((line[i] - line[i - 1]).normalized());
        const Eigen::Vector2d pl = m + n * kSideProbe, pr = m - n * kSideProbe;
        const bool in_l = edges->inside(pl), in_r = edges->inside(pr);
        int high = 0;
        if (in_l != in_r) {
          high = in_l ? -1 : 1;  // the side away from the carriageway
        } else if (in_l) {       // within the carriageway: the side off the road lanelets (a cycle lane)
          const bool ml = region::contains(motor, pl), mr = region::contains(motor, pr);
          high = ml != mr ? (ml ? -1 : 1) : 1;
          unclear += ml == mr;
        } else {  // off it: the side farther from it
          high = edges->distance(pl) >= edges->distance(pr) ? 1 : -1;
        }
        sides.push_back(high);
        raised_segments.push_back(
            {line[i - 1], line[i], group, curb_height.back(), high, i == 1, i + 1 == line.size()});
      }
      if (unclear) unclear_curbs.push_back(id);
      curb_high_side.push_back(std::move(sides));
      ++group;
    }
    for (const auto& [id, s] : map.lines) {
      if (s.type != "road_border") continue;
      ++report.road_borders;
      const Polyline2d line = flat(s.points);
      for (size_t i = 1; i < line.size(); ++i)
        if (edges->distance(0.5 * (line[i - 1] + line[i])) <= kOnEdge)
          raised_segments.push_back({line[i - 1], line[i], group, 0, 0, i == 1, i + 1 == line.size()});
      ++group;
    }
    // The carriageway's edge where the map draws neither: flush.
    const SegmentIndex borders(border_segments);
    for (const auto& path : world.carriageway) {
      const Polyline2d ring = region::to_polyline(path, true);
      bool run = false;
      for (size_t i = 1; i < ring.size(); ++i) {
        const double length = (ring[i] - ring[i - 1]).norm();
        const int n = std::max(1, int(std::ceil(length / kEdgePiece)));
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector2d a = ring[i - 1] + (ring[i] - ring[i - 1]) * (double(k) / n);
          const Eigen::Vector2d b = ring[i - 1] + (ring[i] - ring[i - 1]) * (double(k + 1) / n);
          const auto near = borders.nearest(0.5 * (a + b));
          const bool free = !near || near->distance > kOnEdge;
          if (free && !run) ++group;
          if (free) raised_segments.push_back({a, b, group, 0, 0, false, false});
          run = free;
        }
      }
    }
    if (!unclear_curbs.empty()) {
      std::string ids;
      for (const Lanelet2Id id : unclear_curbs) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
      report.warnings.push_back(std::to_string(unclear_curbs.size()) +
                                " curbstones run inside the carriageway with road on both sides somewhere (raised on "
                                "their left there): " +
                                ids);
    }
    mark_free_ends(raised_segments);
    raised = std::make_shared<const RaisedEdges>(raised_segments);
    auto r = raised;
    auto t = terrain;
    world.raised_level = [r, t](const Eigen::Vector2d& p) { return float(t(p) + (*r)(p)); };
    if (curbstones.empty())
      report.warnings.push_back(
          "the map has no curbstones: the curb methods (curb map, curb matching) will find nothing");
  }

  void bounds_and_regions() {
    Eigen::AlignedBox2d box;
    for (const auto& [id, s] : map.lines)
      for (const auto& p : s.points) box.extend(p.head<2>());
    for (const auto& l : map.lanelets) {
      for (const auto& p : l.left_points) box.extend(p.head<2>());
      for (const auto& p : l.right_points) box.extend(p.head<2>());
    }
    for (const auto& a : map.areas)
      for (const auto& ring : a.outer)
        for (const auto& p : ring) box.extend(p.head<2>());
    box.min() -= Eigen::Vector2d::Constant(params.geometry.margin);
    box.max() += Eigen::Vector2d::Constant(params.geometry.margin);
    world.bounds = box;
  }

  // The curbs' faces, and the ground: pavement, sidewalks and islands, parking, vegetation, the rest.
  void ground_mesh() {
    region::Paths ribbons;
    for (size_t c = 0; c < curbstones.size(); ++c)
      ribbons = region::unite(ribbons, region::strip(world.curbs[c], ribbon_half(c), false));
    region::Paths paved, parking, vegetation;
    for (const auto& a : map.areas) {
      if (a.subtype == "walkway" || a.subtype == "traffic_island") {
        paved = region::unite(paved, area_region(a.outer, a.inner));
        (a.subtype == "walkway" ? report.walkway_areas : report.traffic_islands)++;
      } else if (a.subtype == "parking") {
        parking = region::unite(parking, area_region(a.outer, a.inner));
      } else if (a.subtype == "vegetation") {
        vegetation = region::unite(vegetation, area_region(a.outer, a.inner));
      }
    }
    paved = region::unite(paved, cycle_tracks);
    world.sidewalks = region::unite(world.carriageway, paved);

    const RoadSurface& surface = *world.surface;
    const auto pavement = [&surface](const Eigen::Vector2d& p) { return float(surface.carriageway(p)); };
    region::mesh_region(region::subtract(world.carriageway, ribbons), kRoadTile, pavement, mat("asphalt"), world.mesh,
                        kRoadTile);
    const Eigen::AlignedBox2d& b = world.bounds;
    region::Paths off = region::subtract(region::rectangle(b.center(), {1, 0}, b.sizes().x() / 2, b.sizes().y() / 2),
                                         region::unite(world.carriageway, ribbons));
    paved = region::intersect(off, paved);
    parking = region::subtract(region::intersect(off, parking), paved);
    vegetation = region::subtract(region::intersect(off, vegetation), region::unite(paved, parking));
    off = region::subtract(off, region::unite(region::unite(paved, parking), vegetation));
    region::mesh_region(paved, kPavedTile, world.raised_level, mat("sidewalk"), world.mesh, kPavedSquare);
    region::mesh_region(parking, kPavedTile, world.raised_level, mat("asphalt"), world.mesh, kPavedSquare);
    region::mesh_region(vegetation, kGroundTile, world.raised_level, mat("grass"), world.mesh, kGroundSquare);
    region::mesh_region(off, kGroundTile, world.raised_level, mat("grass"), world.mesh, kGroundSquare);
    for (size_t c = 0; c < curbstones.size(); ++c) curb_faces(c);
  }

  double ribbon_half(size_t c) const { return face_run(curb_profile[c], curb_height[c]) + kRibbonMargin; }

  // One curbstone's face, with a strip of low ground in front and of its top behind (the ground meshes
  // stop ribbon_half() from the line): per segment, offsets along the raised side's normal, mitred
  // where the neighbouring segment is raised on the same side.
  void curb_faces(size_t c) {
    const Polyline2d& line = world.curbs[c];
    const std::vector<int>& high = curb_high_side[c];
    const double run = face_run(curb_profile[c], curb_height[c]), half = ribbon_half(c);
    constexpr int kFaceSamples = 3;  // up a rolled face
    const int samples = curb_profile[c] == CurbProfile::rolled ? kFaceSamples : 1;
    const MaterialId concrete = mat("curb_concrete");
    auto seg_normal = [&](size_t i) {  // raised side of segment i (from line[i] to line[i + 1])
      return Eigen::Vector2d(left_normal((line[i + 1] - line[i]).normalized()) * high[i]);
    };
    // Offset direction at vertex v for segment i: mitred with the neighbour when it agrees.
    auto offset_dir = [&](size_t i, size_t v) {
      const Eigen::Vector2d n = seg_normal(i);
      const size_t j = v == i ? i - 1 : i + 1;  // the neighbour sharing vertex v
      if ((v == i && i == 0) || (v == i + 1 && i + 2 >= line.size()) || high[j] != high[i]) return n;
      const Eigen::Vector2d m = n + seg_normal(j);
      if (m.norm() < 1e-6) return n;
      const Eigen::Vector2d u = m.normalized();
      return Eigen::Vector2d(u / std::max(0.5, u.dot(n)));  // mitre, clipped at sharp corners
    };
    for (size_t i = 0; i + 1 < line.size(); ++i) {
      std::array<std::vector<Eigen::Vector3f>, 2> section;  // per end: low edge .. top edge
      for (int e = 0; e < 2; ++e) {
        const size_t v = i + size_t(e);
        const Eigen::Vector2d p = line[v], n = offset_dir(i, v);
        const Eigen::Vector2d low = p - n * half, top = p + n * half;
        const double z_low = edges->inside(p - n * (half + kSideProbe)) ? world.surface->carriageway(low)
                                                                        : double(world.raised_level(low));
        const double z_top = world.raised_level(top);
        auto& s = section[size_t(e)];
        auto put = [&](const Eigen::Vector2d& q, double z) { s.emplace_back(float(q.x()), float(q.y()), float(z)); };
        put(low, z_low);
        put(p, z_low);
        for (int k = 1; k <= samples; ++k) {
          const double u = double(k) / samples;
          put(p + n * (run * u), z_low + (z_top - z_low) * face_rise(curb_profile[c], u));
        }
        put(top, z_top);
      }
      const auto base = static_cast<uint32_t>(world.mesh.vertices.size());
      const auto m = static_cast<uint32_t>(section[0].size());
      for (const auto& s : section) world.mesh.vertices.insert(world.mesh.vertices.end(), s.begin(), s.end());
      // Winding: counter-clockwise seen from the low side / from above for either orientation.
      const bool flip = high[i] < 0;
      for (uint32_t k = 0; k + 1 < m; ++k) {
        const uint32_t a0 = base + k, a1 = base + k + 1, b0 = base + m + k, b1 = base + m + k + 1;
        if (flip) {
          world.mesh.add_triangle(a0, a1, b1, concrete);
          world.mesh.add_triangle(a0, b1, b0, concrete);
        } else {
          world.mesh.add_triangle(a0, b1, a1, concrete);
          world.mesh.add_triangle(a0, b0, b1, concrete);
        }
      }
    }
  }

  // ------------------------------------------------------------------------------------------------
  void paint() {
    const MaterialId lane = mat("lane_paint"), zebra = mat("crosswalk_paint");
    const double z = params.geometry.paint_height;
    const auto g = [this](const Eigen::Vector2d& p) { return ground(p); };
    auto strip = [&](const Polyline2d& line, double width, bool dashed, double dash, double gap, MaterialId m) {
      if (!dashed) return add_paint_line(world.mesh, line, width / 2, g, z, m, &painter);
      for (const auto& piece : dashes(line, dash, gap)) add_paint_line(world.mesh, piece, width / 2, g, z, m, &painter);
    };
    std::set<Lanelet2Id> zebra_done;
    // Zebra crossings: between the two zebra_marking bounds of a lanelet, stripes across it from one
    // bound to the other, repeated along it (the bounds are the crossing's edges).
    for (const auto& l : map.lanelets) {
      const auto* left = map.line(l.left);
      const auto* right = map.line(l.right);
      if (!left || !right || left->type != "zebra_marking" || right->type != "zebra_marking") continue;
      const Polyline2d a = flat(l.left_points), b = flat(l.right_points);
      if (a.size() < 2 || b.size() < 2) continue;
      const double la = polyline_length(a), lb = polyline_length(b), len = 0.5 * (la + lb);
      const double period = std_.zebra_stripe + std_.zebra_gap;
      const int n = int(std::floor((len + std_.zebra_gap) / period));
      const double start = 0.5 * (len - (n * period - std_.zebra_gap));
      for (int k = 0; k < n; ++k) {
        const double u0 = (start + k * period) / len, u1 = u0 + std_.zebra_stripe / len;
        stripe(sample_polyline(a, u0 * la).point, sample_polyline(a, u1 * la).point, sample_polyline(b, u1 * lb).point,
               sample_polyline(b, u0 * lb).point, g, z, zebra);
        ++report.zebra_stripes;
      }
      zebra_done.insert({l.left, l.right});
    }
    for (const auto& [id, s] : map.lines) {
      const Polyline2d line = flat(s.points);
      if (line.size() < 2) continue;
      const std::string& t = s.type;
      if (t == "line_thin" || t == "line_thick") {
        const double w = t == "line_thin" ? std_.thin_width : std_.thick_width;
        // Lanelet2 LinestringTagging.md: the first word of a double line's subtype is its left line
        // (in the way's direction). No subtype: solid.
        const std::string sub = s.subtype.empty() ? "solid" : s.subtype;
        const auto us = sub.find('_');
        if (us == std::string::npos && (sub == "solid" || sub == "dashed")) {
          strip(line, w, sub == "dashed", std_.dash, std_.gap, lane);
        } else if (us != std::string::npos) {
          const std::string l = sub.substr(0, us), r = sub.substr(us + 1);
          const double off = 0.5 * (w + std_.double_spacing);
          strip(offset_polyline(line, off, false), w, l == "dashed", std_.dash, std_.gap, lane);
          strip(offset_polyline(line, -off, false), w, r == "dashed", std_.dash, std_.gap, lane);
        } else {
          ++report.not_built[t + " " + sub + " line"];
          continue;
        }
        ++report.paint_lines[t + " " + sub];
      } else if (t == "stop_line") {
        strip(line, std_.stop_width, false, 0, 0, lane);
        ++report.stop_lines;
      } else if (t == "pedestrian_marking") {
        strip(line, std_.pedestrian_width, true, std_.pedestrian_dash, std_.pedestrian_gap, lane);
        ++report.pedestrian_markings;
      } else if (t == "bike_marking") {
        strip(line, std_.bike_width, true, std_.bike_dash, std_.bike_gap, lane);
        ++report.bike_markings;
      } else if (t == "zebra_marking") {
        ++report.zebra_markings;
        if (zebra_done.count(id)) continue;
        // A zebra bound without a partner: stripes of the standard's length centred on it.
        const double len = polyline_length(line), period = std_.zebra_stripe + std_.zebra_gap;
        for (double s0 = std_.zebra_stripe / 2; s0 <= len; s0 += period) {
          const PolylineSample at = sample_polyline(line, s0);
          add_marking_quad(world.mesh, at.point, left_normal(at.tangent), std_.zebra_length / 2, std_.zebra_stripe / 2,
                           g, z, zebra, painter);
          ++report.zebra_stripes;
        }
        ++report.not_built["zebra_marking with no partner bound: stripes centred on it"];
      }
    }
  }

  // A quad a-b-c-d (a-b along one bound, d-c along the other) draped over the ground, in pieces across.
  template <class Ground>
  void stripe(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d,
              const Ground& g, double z, MaterialId m) {
    const int pieces = std::max(1, int(std::ceil(std::max((d - a).norm(), (c - b).norm()) / kPaintPiece)));
    const auto base = static_cast<uint32_t>(world.mesh.vertices.size());
    bool fresh = false;  // one marking: its own paint (sim/paint_wear.hpp), worn in pieces
    m = painter.marking(m, marking_key(0.25 * (a + b + c + d)), fresh);
    for (int k = 0; k <= pieces; ++k) {
      const double f = double(k) / pieces;
      for (const Eigen::Vector2d& p : {Eigen::Vector2d(a + (d - a) * f), Eigen::Vector2d(b + (c - b) * f)})
        world.mesh.vertices.emplace_back(float(p.x()), float(p.y()), float(g(p) + z));
    }
    for (uint32_t k = 0; k < uint32_t(pieces); ++k) {
      const double f = (k + 0.5) / pieces;
      if (painter.worn(0.5 * (a + (d - a) * f + b + (c - b) * f), fresh)) continue;
      world.mesh.add_triangle(base + 2 * k, base + 2 * k + 1, base + 2 * k + 3, m);
      world.mesh.add_triangle(base + 2 * k, base + 2 * k + 3, base + 2 * k + 2, m);
    }
  }

  // ------------------------------------------------------------------------------------------------
  // Walls, fences and guard rails along their ways, a box per segment.
  void barriers() {
    const MaterialId building = mat("building"), metal = mat("metal");
    for (const auto& [id, s] : map.lines) {
      const Polyline2d line = flat(s.points);
      if (line.size() < 2) continue;
      const bool wall = s.type == "wall", fence = s.type == "fence", rail = s.type == "guard_rail";
      if (!wall && !fence && !rail) continue;
      (wall ? report.walls : fence ? report.fences : report.guard_rails)++;
      for (size_t i = 1; i < line.size(); ++i) {
        const Eigen::Vector2d d = line[i] - line[i - 1], mid = 0.5 * (line[i] + line[i - 1]);
        const float yaw = float(std::atan2(d.y(), d.x())), half = float(d.norm() / 2);
        const float base = float(ground(mid));
        if (wall || fence) {
          const double h = number_tag(s.tags, "height").value_or(wall ? params.wall_height : params.fence_height);
          const double thick = wall ? params.wall_thickness : params.fence_thickness;
          add_box(world.mesh, mid.cast<float>(), {half, float(thick / 2)}, yaw, base - float(kFoundation),
                  base + float(h), wall ? building : metal);
          continue;
        }
        const float top = base + float(params.guard_rail_height);
        add_box(world.mesh, mid.cast<float>(), {half, 0.05f}, yaw, top - float(params.guard_rail_beam), top, metal);
        const double len = d.norm();
        for (double at = 0; at < len; at += params.guard_rail_post_spacing) {
          const Eigen::Vector2d p = line[i - 1] + d * (at / len);
          const float foot = float(ground(p));
          add_box(world.mesh, p.cast<float>(), {0.05f, 0.05f}, yaw, foot - float(kFoundation),
                  top - float(params.guard_rail_beam), metal);
        }
      }
    }
  }

  void building(const region::Paths& footprint, const std::vector<Polyline2d>& rings, double height) {
    const MaterialId m = mat("building");
    double base = std::numeric_limits<double>::infinity();
    for (const auto& ring : rings)
      for (const auto& p : ring) base = std::min(base, double(world.raised_level(p)));
    if (!std::isfinite(base)) return;
    const float z0 = float(base - kFoundation), z1 = float(base + height);
    for (const auto& ring : rings)
      for (size_t i = 0; i < ring.size(); ++i) {
        const Eigen::Vector2d a = ring[i], b = ring[(i + 1) % ring.size()];
        const auto v = static_cast<uint32_t>(world.mesh.vertices.size());
        world.mesh.vertices.emplace_back(float(a.x()), float(a.y()), z0);
        world.mesh.vertices.emplace_back(float(b.x()), float(b.y()), z0);
        world.mesh.vertices.emplace_back(float(b.x()), float(b.y()), z1);
        world.mesh.vertices.emplace_back(float(a.x()), float(a.y()), z1);
        world.mesh.add_triangle(v, v + 1, v + 2, m);
        world.mesh.add_triangle(v, v + 2, v + 3, m);
      }
    region::mesh_region(
        footprint, kRoofTile, [z1](const Eigen::Vector2d&) { return z1; }, m, world.mesh);
    ++report.buildings;
  }

  void buildings() {
    for (const auto& a : map.areas) {
      if (a.subtype != "building") continue;
      std::vector<Polyline2d> rings;
      for (const auto* set : {&a.outer, &a.inner})
        for (const auto& r : *set) rings.push_back(flat(r));
      building(area_region(a.outer, a.inner), rings, number_tag(a.tags, "height").value_or(params.building_height));
    }
    for (const auto& [id, s] : map.lines) {
      if (s.type != "building") continue;
      Polyline2d ring = flat(s.points);
      if (ring.size() > 2 && (ring.front() - ring.back()).norm() < kJoin) ring.pop_back();
      if (ring.size() < 3) {
        ++report.not_built["building line that is not closed"];
        continue;
      }
      building(region::unite({region::to_path(ring)}, {}), {ring},
               number_tag(s.tags, "height").value_or(params.building_height));
    }
  }

  // Trees on a global grid inside each vegetation area; hedges just inside its edge, except near the road.
  void vegetation() {
    const MaterialId leaves = mat("vegetation");
    const region::Paths near_road = region::offset(world.carriageway, params.hedge_clearance);
    for (const auto& a : map.areas) {
      if (a.subtype != "vegetation") continue;
      ++report.vegetation_areas;
      const region::Paths area = area_region(a.outer, a.inner);
      const region::Paths inner = region::offset(area, -params.tree_inset);
      Eigen::AlignedBox2d box;
      for (const auto& path : inner)
        for (const auto& p : region::to_polyline(path, false)) box.extend(p);
      if (!box.isEmpty()) {
        const double sp = params.tree_spacing;
        for (double x = std::ceil(box.min().x() / sp) * sp; x <= box.max().x(); x += sp)
          for (double y = std::ceil(box.min().y() / sp) * sp; y <= box.max().y(); y += sp) {
            const Eigen::Vector2d p(x, y);
            if (!region::contains(inner, p) || edges->inside(p)) continue;
            add_tree(world.mesh, {float(x), float(y), world.raised_level(p)}, float(params.tree_height),
                     float(params.tree_crown_radius), leaves);
            ++report.trees;
          }
      }
      std::vector<Polyline2d> rings;
      for (const auto& path : region::offset(area, -(params.hedge_inset + params.hedge_depth / 2)))
        rings.push_back(region::to_polyline(path, true));
      for (const auto& piece : region::clip_lines_outside(rings, near_road)) {
        if (polyline_length(piece) < params.hedge_depth) continue;
        for (size_t i = 1; i < piece.size(); ++i) {
          const Eigen::Vector2d d = piece[i] - piece[i - 1], mid = 0.5 * (piece[i] + piece[i - 1]);
          if (d.norm() < 1e-3) continue;
          const float base = world.raised_level(mid);
          add_box(world.mesh, mid.cast<float>(), {float(d.norm() / 2), float(params.hedge_depth / 2)},
                  float(std::atan2(d.y(), d.x())), base - 0.05f, base + float(params.hedge_height), leaves);
        }
        ++report.hedges;
      }
    }
  }

  // Parking: stalls in rows along the area's long axis (perpendicular stalls where the area is deep
  // enough, else parallel ones), kept if wholly inside the area and off the carriageway; a share of
  // them, chosen by a generator seeded from params.seed, holds a parked car.
  void parking() {
    std::mt19937_64 rng(params.seed);
    std::optional<TriangleMesh> car;
    Eigen::AlignedBox3f car_box;
    for (const auto& a : map.areas) {
      if (a.subtype != "parking") continue;
      ++report.parking_areas;
      const region::Paths area = area_region(a.outer, a.inner);
      if (area.empty() || a.outer.empty()) continue;
      Polyline2d all;
      for (const auto& ring : a.outer)
        for (const auto& p : flat(ring)) all.push_back(p);
      const Frame f = long_axis_frame(all);
      struct Stall {
        Eigen::Vector2d centre, heading;
      };
      std::vector<Stall> stalls;
      auto try_row = [&](double v_mid, double along, double across, const Eigen::Vector2d& heading) {
        const int n = int(std::floor((f.u1 - f.u0) / along + 1e-9));
        const double start = f.u0 + 0.5 * ((f.u1 - f.u0) - n * along);
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector2d c = f.u * (start + (k + 0.5) * along) + f.v * v_mid;
          const region::Paths rect = region::rectangle(c, f.u, along / 2, across / 2);
          const double full = along * across;
          if (region::area(region::intersect(rect, area)) < full * (1 - 1e-3)) continue;
          if (region::area(region::intersect(rect, world.carriageway)) > 1e-3) continue;
          stalls.push_back({c, heading});
        }
      };
      const double depth = f.v1 - f.v0;
      if (depth + 1e-9 >= std_.stall_depth) {
        // Rows back to back, a row on each side of each aisle: row, aisle, row, row, aisle, row ...
        double v = f.v0;
        for (int row = 0; v + std_.stall_depth <= f.v1 + 1e-9; ++row) {
          try_row(v + std_.stall_depth / 2, std_.stall_width, std_.stall_depth, f.v);
          v += std_.stall_depth + (row % 2 == 0 ? kAisle : 0.0);
        }
      } else if (depth + 1e-9 >= std_.parallel_width) {
        try_row(0.5 * (f.v0 + f.v1), std_.parallel_length, std_.parallel_width, f.u);
      }
      report.parking_stalls += int(stalls.size());
      std::shuffle(stalls.begin(), stalls.end(), rng);
      const auto taken = size_t(std::llround(std::clamp(params.parking_occupancy, 0.0, 1.0) * double(stalls.size())));
      for (size_t k = 0; k < taken; ++k) {
        if (!car) {
          car = load_actor_mesh(actors_dir, ActorType::car, materials);
          for (const auto& p : car->vertices) car_box.extend(p);
        }
        const bool flip = std::uniform_int_distribution<int>(0, 1)(rng) == 1;  // nose in or out
        const Eigen::Vector2d h = flip ? Eigen::Vector2d(-stalls[k].heading) : stalls[k].heading;
        const Eigen::Vector2d& c = stalls[k].centre;
        Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
        pose.translate(Eigen::Vector3f(float(c.x()), float(c.y()), world.raised_level(c)));
        pose.rotate(Eigen::AngleAxisf(float(std::atan2(h.y(), h.x())), Eigen::Vector3f::UnitZ()));
        world.mesh.append(*car, pose);
        ++report.parked_vehicles;
      }
    }
  }

  // Traffic lights and signs: the way is the plate's lower edge (Lanelet2 LinestringTagging.md); a pole
  // carries it, standing behind the carriageway's edge when the plate hangs over the road.
  void poles() {
    const MaterialId metal = mat("metal"), plate = mat("retro_reflector");
    for (const auto& [id, s] : map.lines) {
      const bool light = s.type == "traffic_light", sign = s.type == "traffic_sign";
      if (!light && !sign) continue;
      if (s.points.empty()) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& p : s.points) mean += p / double(s.points.size());
      const Eigen::Vector2d at = mean.head<2>();
      const Eigen::Vector2d d = s.points.back().head<2>() - s.points.front().head<2>();
      const double length = d.norm();
      const double width = length >= 0.2 ? length : (light ? 0.3 : std_.sign_size);
      const double height = number_tag(s.tags, "height").value_or(light ? params.light_height : width);
      const double g = ground(at);
      // The map's z is the lower edge when it stands clearly above the ground there.
      const double bottom = mean.z() > g + 1.0 ? mean.z() : g + (light ? params.light_bottom : std_.sign_bottom);
      const float yaw = float(length > 1e-6 ? std::atan2(d.y(), d.x()) : 0.0);
      add_box(world.mesh, at.cast<float>(), {float(width / 2), kPlateThickness / 2}, yaw, float(bottom),
              float(bottom + height), plate);
      // The pole stands behind the plate, on the side away from the road (the plate faces the traffic).
      Eigen::Vector2d foot = at;
      const auto out = edges->nearest_outside(at);
      if (out && edges->inside(at) && (out->first - at).norm() <= kMaxArm)
        foot = out->first + out->second * kPoleClearance;
      else if (out)
        foot = at + out->second * double(kPlateThickness / 2 + kPoleRadius + 0.01f);
      const float top = float(bottom + height), base = float(ground(foot));
      add_frustum(world.mesh, {float(foot.x()), float(foot.y()), base}, kPoleRadius, kPoleTopRadius, top - base, 12,
                  metal);
      if ((foot - at).norm() > 0.2) {  // an arm from the pole's top to the plate
        const Eigen::Vector2d arm = at - foot;
        add_box(world.mesh, (0.5 * (at + foot)).cast<float>(), {float(arm.norm() / 2), 0.05f},
                float(std::atan2(arm.y(), arm.x())), top - 0.1f, top, metal);
      }
      (light ? report.traffic_lights : report.traffic_signs)++;
    }
  }

  // What was read but not built, by kind.
  void not_built() {
    static const std::set<std::string> built_lines = {
        "curbstone",     "road_border",        "line_thin",    "line_thick", "stop_line",
        "zebra_marking", "pedestrian_marking", "bike_marking", "wall",       "fence",
        "guard_rail",    "traffic_light",      "traffic_sign", "building"};
    for (const auto& [id, s] : map.lines) {
      if (s.type == "virtual")
        ++report.not_built["virtual: not drawn"];
      else if (!built_lines.count(s.type))
        ++report.not_built[(s.type.empty() ? std::string("untyped") : s.type) + " line"];
    }
    static const std::set<std::string> built_areas = {"walkway", "traffic_island", "parking", "vegetation", "building"};
    for (const auto& a : map.areas)
      if (!built_areas.count(a.subtype)) ++report.not_built[(a.subtype.empty() ? "untyped" : a.subtype) + " area"];
    for (const auto& r : map.regulatory)
      ++report.not_built[(r.subtype.empty() ? "untyped" : r.subtype) + " regulatory element (rules, no geometry)"];
    for (const auto& [what, n] : map.other_relations) report.not_built[what + " relation"] += n;
    for (const auto& w : map.warnings) report.warnings.push_back(w);
  }
};

}  // namespace

Lanelet2Standards lanelet2_standards(const std::string& country) {
  Lanelet2Standards s;  // the defaults are Germany's
  s.country = country == "us" ? "us" : "de";
  if (s.country != "us") return s;
  constexpr double kInch = 0.0254, kFoot = 0.3048;
  s.cross_slope = 0.02;
  s.crown_distance = 12 * kFoot;
  s.curb_high = 6 * kInch;
  s.curb_low = 4 * kInch;
  s.thin_width = 6 * kInch;
  s.thick_width = 12 * kInch;
  s.dash = 10 * kFoot;
  s.gap = 30 * kFoot;
  s.double_spacing = 4 * kInch;
  s.stop_width = 12 * kInch;
  s.zebra_stripe = 24 * kInch;
  s.zebra_gap = 24 * kInch;
  s.zebra_length = 10 * kFoot;  // MUTCD 3B.18: crosswalks at least 6 ft wide; 10 ft is common
  s.pedestrian_width = 6 * kInch;
  s.bike_width = 6 * kInch;
  s.bike_dash = 2 * kFoot;
  s.bike_gap = 4 * kFoot;
  s.stall_width = 8.5 * kFoot;
  s.stall_depth = 18 * kFoot;
  s.parallel_width = 8 * kFoot;
  s.parallel_length = 22 * kFoot;
  s.sign_bottom = 7 * kFoot;
  s.sign_size = 30 * kInch;
  return s;
}

std::string Lanelet2BuildReport::summary() const {
  std::ostringstream o;
  o << "standards: " << country << "; cross-fall " << cross_fall << "\n";
  o << "carriageway: " << road_lanelets << " road lanelets";
  if (cycle_tracks) o << ", " << cycle_tracks << " cycle tracks behind curbs";
  o << "\ncurbs: " << curbstones_high << " high, " << curbstones_low << " low (" << int(std::round(curb_length_m))
    << " m); road borders: " << road_borders << "\n";
  o << "paint:";
  for (const auto& [k, n] : paint_lines) o << " " << k << " " << n << ",";
  o << " stop lines " << stop_lines << ", zebra markings " << zebra_markings << " (" << zebra_stripes
    << " stripes), pedestrian markings " << pedestrian_markings << ", bike markings " << bike_markings << "\n";
  o << "walls " << walls << ", fences " << fences << ", guard rails " << guard_rails << ", buildings " << buildings
    << "\n";
  o << "walkways " << walkway_areas << ", traffic islands " << traffic_islands << ", vegetation areas "
    << vegetation_areas << " (" << trees << " trees, " << hedges << " hedges)\n";
  o << "parking areas " << parking_areas << ": " << parked_vehicles << " parked vehicles in " << parking_stalls
    << " stalls\n";
  o << "traffic lights " << traffic_lights << ", traffic signs " << traffic_signs << "\n";
  write_not_built(o, not_built, warnings);
  return o.str();
}

World build_lanelet2_world(const Lanelet2Map& map, const Lanelet2WorldParams& params, const MaterialTable& materials,
                           const std::string& actors_dir, Lanelet2BuildReport* report) {
  Lanelet2BuildReport local;
  Builder b(map, params, materials, actors_dir, report ? *report : local);
  b.report = {};
  b.world.name = map.file;
  b.world.origin = map.origin;
  b.standards();
  b.carriageway();
  b.surface();
  b.curbs();
  b.bounds_and_regions();
  b.ground_mesh();
  b.paint();
  b.barriers();
  b.buildings();
  b.vegetation();
  b.parking();
  b.poles();
  b.not_built();
  b.world.paint_materials = b.painter.variants();
  return std::move(b.world);
}

std::shared_ptr<const Lanelet2Source> load_lanelet2_source(const std::string& file, const std::string& where,
                                                           const Lanelet2WorldParams& params,
                                                           const Lanelet2ReadOptions& read) {
  auto source = std::make_shared<Lanelet2Source>();
  source->file = file;
  source->where = where;
  source->map = read_lanelet2(file, read);
  source->graph = build_lane_graph(source->map);
  source->params = params;
  return source;
}

}  // namespace lidarloop
