#include "sim/world_builder.hpp"

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <unordered_map>

#include "common/input_error.hpp"
#include "sim/actor_assets.hpp"
#include "sim/curb_band.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/mesh_shapes.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kGroundTile = 8.0;       // m; verge triangles are at most this size near edges
constexpr double kVergeSquare = 4.0;      // m; verge squares sample the terrain's hills this densely
constexpr double kRoadTile = 0.5;         // m; pavement and sidewalks: crown, roughness, ramps
constexpr double kCurbStation = 0.5;      // m between cross-sections of the curb band
constexpr double kIntersectionPad = 2.0;  // m beyond the corner radius where lane paint stops
constexpr double kCrosswalkPad = 1.0;     // m before a crosswalk where lane paint stops
// Work zones. Cones: MUTCD (2009) 6F.64, at least 28 in (0.71 m) tall; for night use a 6 in (0.15 m)
// white retro-reflective band 3 to 4 in below the top (0.47-0.62 m; the 4 in band below it is left out),
// standing 1 cm proud of the cone's surface; spaced in feet at about the speed in mph (6C.08: 30 km/h ~
// 20 mph ~ 6 m), 0.3 m inside the closed side. Barriers: the New Jersey / F-shape concrete safety
// barrier, 32 in (0.81 m) tall, 24 in (0.61 m) at its base, in 12.5 ft (3.8 m) segments.
constexpr double kConeSpacing = 6.0, kConeInset = 0.3;                                                   // m
constexpr float kConeHeight = 0.71f, kConeBaseRadius = 0.18f, kConeTopRadius = 0.03f;                    // m
constexpr float kBandLow = 0.47f, kBandHigh = 0.62f, kBandRadiusLow = 0.091f, kBandRadiusHigh = 0.059f;  // m
constexpr double kBarrierLength = 3.8, kBarrierJoint = 0.05;         // m; a barrier segment and half the gap between
constexpr float kBarrierHeight = 0.81f, kBarrierHalfWidth = 0.305f;  // m
// A construction zone's temporary kerb: precast blocks 1 m long and 0.3 m wide (assumption: the common
// size of bolt-down kerb units), as high as the road's curb.
constexpr double kKerbBlockLength = 1.0;
constexpr float kKerbHalfWidth = 0.15f;

// Roadside: a hydrant's barrel is this share of its height, its cap narrows to this share of its
// radius; a verge lies a little above the raised ground, so the two do not fight for the same rays; a
// hedge's foot is sunk a little into the ground, so no ray passes under it on a slope.
constexpr float kHydrantBody = 0.8f, kHydrantCapTop = 0.5f;  // -
constexpr double kVergeLift = 0.01, kHedgeSink = 0.05;       // m
constexpr double kFurnitureClearance = 0.2;                  // m from the carriageway to a post's axis
// A curb cross-section this close to a road's half width from its centreline, and facing within this
// much of square to it, runs along that road (otherwise it turns round a junction's corner): hedges
// and verges follow only those.
constexpr double kAlongRoad = 0.3;        // m
constexpr double kAlongRoadFacing = 0.1;  // |sin| of the angle off square
constexpr double kLoweredCell = 2.0;      // m; grid of lowered curb points for look-ups within this

Eigen::Vector2d left_normal(const Eigen::Vector2d& tangent) { return {-tangent.y(), tangent.x()}; }

// Where the curb is lowered: cut for a driveway, a ramp or a bus bay, or tapering down beside one over
// its flares. Roadside objects keep clear of these stretches (they are kept open for vehicles and
// pedestrians), looked up on a coarse grid.
bool lowered(const CurbStation& c) { return c.cut || c.height < c.nominal_height - 1e-6; }

class LoweredCurb {
 public:
  explicit LoweredCurb(const RaisedGround& band) {
    for (const auto& ring : band.rings())
      for (const CurbStation& c : ring)
        if (lowered(c)) cells_[key(cell(c.point, 0), cell(c.point, 1))].push_back(c.point);
  }
  // Whether a lowered curb point lies within `radius` (at most kLoweredCell) of p.
  bool near(const Eigen::Vector2d& p, double radius) const {
    const int64_t i = cell(p, 0), j = cell(p, 1);
    for (int64_t di = -1; di <= 1; ++di)
      for (int64_t dj = -1; dj <= 1; ++dj) {
        const auto it = cells_.find(key(i + di, j + dj));
        if (it == cells_.end()) continue;
        for (const auto& q : it->second)
          if ((q - p).squaredNorm() <= radius * radius) return true;
      }
    return false;
  }

 private:
  static int64_t cell(const Eigen::Vector2d& p, int axis) { return int64_t(std::floor(p[axis] / kLoweredCell)); }
  static int64_t key(int64_t i, int64_t j) { return i * 4000037 + j; }
  std::unordered_map<int64_t, std::vector<Eigen::Vector2d>> cells_;
};

// Runs of consecutive true flags round a ring of n: [first, first + count) modulo n; a ring whose flags
// are all true is one run of n, `closed`.
struct Run {
  size_t first = 0, count = 0;
  bool closed = false;
};
std::vector<Run> runs_of(const std::vector<char>& on) {
  const size_t n = on.size();
  size_t start = 0;
  while (start < n && on[start]) ++start;
  if (start == n) return n ? std::vector<Run>{{0, n, true}} : std::vector<Run>{};
  std::vector<Run> out;
  for (size_t k = 1; k <= n; ++k) {
    const size_t i = (start + k) % n;
    if (!on[i]) continue;
    if (on[(i + n - 1) % n] && !out.empty() && k > 1)
      ++out.back().count;
    else
      out.push_back({i, 1, false});
  }
  return out;
}

// A hedge's cross-section, in metres behind the curb line (negative: over the road) and above the
// ground at its trunks: a bank of `depth` from `setback` back, full height; above `clearance` its
// road-facing side leans out from the curb line to `overhang` in front of it at the top.
std::array<Eigen::Vector2d, 6> hedge_section(const HedgeSpec& h) {
  const double back = h.setback + h.depth;
  return {{{back, 0},
           {back, h.height},
           {-h.overhang, h.height},
           {0, h.clearance},
           {h.setback, h.clearance},
           {h.setback, 0}}};
}

// A hedge along a run of curb cross-sections: its section swept from one to the next (a cap at each
// end of an open run). Points at height 0 are sunk a little into the ground under them.
void add_hedge(TriangleMesh& mesh, const std::vector<const CurbStation*>& run, bool closed, const HedgeSpec& h,
               const std::function<float(const Eigen::Vector2d&)>& ground, MaterialId m) {
  const auto section = hedge_section(h);
  constexpr uint32_t kN = 6;
  const auto base = static_cast<uint32_t>(mesh.vertices.size());
  for (const CurbStation* c : run) {
    const Eigen::Vector2d out = c->normal * c->miter;
    const double level = ground(c->point + out * (h.setback + h.depth / 2));
    for (const Eigen::Vector2d& q : section) {
      const Eigen::Vector2d xy = c->point + out * q.x();
      const double z = q.y() > 0 ? level + q.y() : ground(xy) - kHedgeSink;
      mesh.vertices.emplace_back(float(xy.x()), float(xy.y()), float(z));
    }
  }
  const auto n = uint32_t(run.size());
  for (uint32_t i = 0; i + (closed ? 0 : 1) < n; ++i) {
    const uint32_t a = base + i * kN, b = base + ((i + 1) % n) * kN;
    for (uint32_t k = 0; k < kN; ++k) {
      const uint32_t k1 = (k + 1) % kN;
      mesh.add_triangle(a + k, a + k1, b + k1, m);
      mesh.add_triangle(a + k, b + k1, b + k, m);
    }
  }
  if (closed) return;
  for (const uint32_t end : {base, base + (n - 1) * kN})  // a fan from the back top corner
    for (uint32_t k = 2; k + 1 <= kN; ++k) mesh.add_triangle(end + 1, end + k, end + (k + 1) % kN, m);
}

// The part of a centreline within length/2 of arc length `at`, sampled every kPaintPiece.
Polyline2d stretch_of(const Polyline2d& centreline, double at, double length) {
  const double from = std::max(0.0, at - length / 2), to = std::min(polyline_length(centreline), at + length / 2);
  Polyline2d out;
  const int pieces = std::max(1, int(std::ceil((to - from) / kPaintPiece)));
  for (int k = 0; k <= pieces; ++k) out.push_back(sample_polyline(centreline, from + (to - from) * k / pieces).point);
  return out;
}

struct Builder {
  const WorldDescription& desc;
  const MaterialTable& materials;
  const std::string& actors_dir;
  World world;
  region::Paths no_lane_paint;                    // intersections and crosswalk approaches
  MarkingPainter painter{desc.paint, materials};  // each marking's wear (uniform without desc.paint)

  MaterialId mat(const std::string& name) const { return materials.id(name, desc.file); }

  void build_regions() {
    const double r = desc.geometry.corner_radius;
    region::Paths road_union, sidewalk_union;
    std::vector<region::Paths> strips;
    for (const auto& road : desc.roads) {
      strips.push_back(region::strip(road.centreline, road.width / 2, road.closed));
      road_union = region::unite(road_union, strips.back());
      sidewalk_union = region::unite(sidewalk_union,
                                     region::strip(road.centreline, road.width / 2 + road.sidewalk_width, road.closed));
    }
    world.carriageway = region::closing(road_union, r);
    world.sidewalks = region::closing(sidewalk_union, r);
    // Where two roads overlap is an intersection: no lane paint there or around its rounded corners.
    for (size_t i = 0; i < strips.size(); ++i)
      for (size_t j = i + 1; j < strips.size(); ++j) {
        const region::Paths overlap = region::intersect(strips[i], strips[j]);
        if (!overlap.empty())
          no_lane_paint = region::unite(no_lane_paint, region::offset(overlap, r + kIntersectionPad));
      }
  }

  void check_off_carriageway(const std::vector<Eigen::Vector2d>& footprint, const std::string& where,
                             const std::string& what, const region::Paths& area, const std::string& area_name) {
    ClipperLib::Path poly = region::to_path(footprint);
    if (!ClipperLib::Orientation(poly)) std::reverse(poly.begin(), poly.end());
    if (region::area(region::intersect({poly}, area)) > 1e-4)
      throw InputError(where + ": " + what + " overlaps the " + area_name);
  }

  void build_ground() {
    const auto& g = desc.geometry;
    // The curb band along the carriageway's edge (Clipper keeps the filled side on the left of every
    // ring, outer or hole), and the raised ground that continues from its top.
    std::vector<Polyline2d> edges;
    for (const auto& c : world.carriageway) edges.push_back(region::to_polyline(c, true));
    const CurbBandWidths band = curb_band_widths(desc);
    auto raised = std::make_shared<const RaisedGround>(curb_stations(edges, desc, *world.surface, kCurbStation),
                                                       world.surface, g, band.outer);
    world.curb_band = raised;
    world.raised_level = [raised](const Eigen::Vector2d& p) { return float((*raised)(p)); };
    curb_lines(raised->rings(), world.curbs, world.curb_kinds);
    region::Paths inner, outer;
    for (const auto& ring : raised->rings()) {
      inner.push_back(region::to_path(offset_ring(ring, -band.inner)));
      outer.push_back(region::to_path(offset_ring(ring, band.outer)));
    }
    inner = region::unite(inner, {});
    outer = region::unite(outer, {});
    world.sidewalks = region::unite(world.sidewalks, outer);

    Eigen::AlignedBox2d box;
    for (const auto& path : world.sidewalks)
      for (const auto& p : region::to_polyline(path, false)) box.extend(p);
    for (const auto& b : desc.buildings) box.extend(b.centre + Eigen::Vector2d::Constant(b.size.norm()));
    for (const auto& b : desc.buildings) box.extend(b.centre - Eigen::Vector2d::Constant(b.size.norm()));
    box.min() -= Eigen::Vector2d::Constant(g.margin);
    box.max() += Eigen::Vector2d::Constant(g.margin);
    world.bounds = box;

    const region::Paths sidewalk = region::subtract(world.sidewalks, outer);
    const region::Paths verge = region::subtract(
        region::rectangle(box.center(), {1, 0}, box.sizes().x() / 2, box.sizes().y() / 2), world.sidewalks);
    const RoadSurface& surface = *world.surface;
    auto pavement = [&surface](const Eigen::Vector2d& p) { return float(surface.carriageway(p)); };
    region::mesh_region(band.inner > 0 ? region::intersect(world.carriageway, inner) : world.carriageway, kRoadTile,
                        pavement, mat("asphalt"), world.mesh, kRoadTile);
    mesh_curb_band(*raised, surface, band, mat("asphalt"), mat("curb_concrete"), world.mesh);
    region::mesh_region(sidewalk, kRoadTile, world.raised_level, mat("sidewalk"), world.mesh, kRoadTile);
    region::mesh_region(verge, kGroundTile, world.raised_level, mat("grass"), world.mesh, kVergeSquare);
  }

  void build_markings() {
    const auto& g = desc.geometry;
    const RoadSurface& surface = *world.surface;
    const auto pavement = [&](const Eigen::Vector2d& p) { return surface.carriageway(p); };
    const double z = g.paint_height;
    const MaterialId lane = mat("lane_paint"), zebra = mat("crosswalk_paint");
    for (const auto& c : desc.crosswalks) {
      const RoadSpec& road = *desc.road(c.road);
      const PolylineSample s = sample_polyline(road.centreline, c.at);
      const Eigen::Vector2d n = left_normal(s.tangent);
      no_lane_paint =
          region::unite(no_lane_paint, region::rectangle(s.point, s.tangent, c.width / 2 + kCrosswalkPad, road.width));
      const double period = g.crosswalk_stripe + g.crosswalk_gap;
      const int stripes = static_cast<int>((road.width - 2 * g.crosswalk_gap) / period);
      for (int k = 0; k < stripes; ++k) {
        const double lateral = (k - (stripes - 1) / 2.0) * period;
        const Eigen::Vector2d centre = s.point + n * lateral;
        add_marking_quad(world.mesh, centre, s.tangent, c.width / 2, g.crosswalk_stripe / 2, pavement, z, zebra,
                         painter);
      }
    }
    for (const auto& sl : desc.stop_lines) {
      const RoadSpec& road = *desc.road(sl.road);
      const PolylineSample s = sample_polyline(road.centreline, sl.at);
      const Eigen::Vector2d n = left_normal(s.tangent);
      const double inset = g.edge_line_inset + road.gutter_width;
      const double lo = sl.side == RoadSide::left ? 0.0 : -road.width / 2 + inset;
      const double hi = sl.side == RoadSide::right ? 0.0 : road.width / 2 - inset;
      add_paint_line(world.mesh, {s.point + n * lo, s.point + n * hi}, g.stop_line_width / 2, pavement, z, lane,
                     &painter);
    }
    // Where the paint changed since the survey (a scenario's world_changes): today's lines there are
    // gone, or redrawn `shift` to the left.
    region::Paths changed;
    for (const auto& c : desc.paint_changes) {
      const RoadSpec& road = *desc.road(c.road);
      changed =
          region::unite(changed, region::strip(stretch_of(road.centreline, c.at, c.length), road.width / 2, false));
    }
    for (const auto& road : desc.roads) {
      // Lane lines as lateral offsets from the centreline; dashed or solid.
      std::vector<std::pair<double, bool>> lines;
      if (road.marking != MarkingStyle::none)
        for (int k = 1; k < road.lanes; ++k)
          lines.emplace_back(-road.width / 2 + k * road.width / road.lanes, road.marking == MarkingStyle::dashed);
      if (road.edge_lines)
        for (double side : {-1.0, 1.0})
          lines.emplace_back(side * (road.width / 2 - g.edge_line_inset - road.gutter_width), false);
      // The pieces of paint as laid out (dashes keep their places along the road), minus `worn`.
      auto paint = [&](const Polyline2d& centreline, bool closed, double shift, const region::Paths& worn) {
        for (const auto& [lateral, dashed] : lines) {
          std::vector<Polyline2d> pieces;
          for (const auto& line :
               region::clip_lines_outside({offset_polyline(centreline, lateral + shift, closed)}, no_lane_paint)) {
            if (!dashed) pieces.push_back(line);
            if (dashed)
              for (const auto& dash : dashes(line, g.dash_length, g.dash_gap)) pieces.push_back(dash);
          }
          if (!worn.empty()) pieces = region::clip_lines_outside(pieces, worn);
          for (const auto& piece : pieces)
            add_paint_line(world.mesh, piece, g.paint_width / 2, pavement, z, lane, &painter);
        }
      };
      paint(road.centreline, road.closed, 0, changed);
      for (const auto& c : desc.paint_changes)
        if (c.road == road.name && c.shift != 0) paint(stretch_of(road.centreline, c.at, c.length), false, c.shift, {});
    }
  }

  // Whether a curb cross-section runs along `road` (not round a junction's corner) at full height (not
  // cut or on a flare), and on which side: +1 left of its centreline, -1 right, 0 neither.
  int along_full_curb(const CurbStation& c, const RoadSpec& road) const {
    if (c.road < 0 || &desc.roads[size_t(c.road)] != &road || lowered(c)) return 0;
    const RoadPoint at = world.surface->nearest_road(c.point);
    if (std::abs(at.distance - road.width / 2) >= kAlongRoad || std::abs(c.normal.dot(at.tangent)) >= kAlongRoadFacing)
      return 0;
    return at.lateral > 0 ? 1 : -1;
  }

  // Hedges follow the curb line's cross-sections, so they bend with it, along the stretch and side of
  // their road where its curb is at full height: they leave cuts and their flares open and stop at a
  // junction's corner.
  void build_hedges(MaterialId leaves) {
    for (const auto& h : desc.hedges) {
      const RoadSpec& road = *desc.road(h.road);
      const double length = polyline_length(road.centreline);
      for (const auto& ring : world.curb_band->rings()) {
        std::vector<char> on(ring.size(), 0);
        for (size_t i = 0; i < ring.size(); ++i) {
          const CurbStation& c = ring[i];
          double from_centre = c.s - h.at;
          if (road.closed) from_centre = std::remainder(from_centre, length);
          if (std::abs(from_centre) > h.length / 2) continue;
          const int side = along_full_curb(c, road);
          if (side == 0 || (side > 0 && h.side == RoadSide::right) || (side < 0 && h.side == RoadSide::left)) continue;
          // A hedge set far back must not reach another road's carriageway.
          const Eigen::Vector2d back = c.point + c.normal * (c.miter * (h.setback + h.depth));
          on[i] = !region::contains(world.carriageway, back);
        }
        for (const Run& run : runs_of(on)) {
          if (run.count < 2) continue;
          std::vector<const CurbStation*> stations;
          for (size_t k = 0; k < run.count; ++k) stations.push_back(&ring[(run.first + k) % ring.size()]);
          add_hedge(world.mesh, stations, run.closed, h, world.raised_level, leaves);
        }
      }
    }
  }

  // Grass verges: a strip `verge_width` wide right behind the curb band, laid over the raised ground
  // along every full-height curb of the road (driveways, ramps and bus bays are paved through it).
  void build_verges() {
    const MaterialId grass = mat("grass");
    const double inner = curb_band_widths(desc).outer;
    for (const auto& ring : world.curb_band->rings()) {
      const size_t n = ring.size();
      std::vector<char> on(n, 0);
      for (size_t i = 0; i < n; ++i) {
        if (ring[i].road < 0) continue;
        const RoadSpec& road = desc.roads[size_t(ring[i].road)];
        on[i] = road.verge_width > 0 && along_full_curb(ring[i], road) != 0;
      }
      for (const Run& run : runs_of(on)) {
        if (run.count < 2) continue;
        const auto base = static_cast<uint32_t>(world.mesh.vertices.size());
        for (size_t k = 0; k < run.count; ++k) {
          const CurbStation& c = ring[(run.first + k) % n];
          const double outer = inner + desc.roads[size_t(c.road)].verge_width;
          for (const double o : {inner, outer}) {
            const Eigen::Vector2d xy = c.point + c.normal * (c.miter * o);
            world.mesh.vertices.emplace_back(float(xy.x()), float(xy.y()), world.raised_level(xy) + float(kVergeLift));
          }
        }
        const auto count = uint32_t(run.count);
        for (uint32_t k = 0; k + (run.closed ? 0 : 1) < count; ++k) {
          const uint32_t a = base + 2 * k, b = base + 2 * ((k + 1) % count);
          world.mesh.add_triangle(a, b, b + 1, grass);
          world.mesh.add_triangle(a, b + 1, a + 1, grass);
        }
      }
    }
  }

  void build_buildings() {
    for (const auto& b : desc.buildings) {
      const MaterialId m = materials.id(b.material, b.where);
      const Eigen::Rotation2D<double> rot(b.yaw);
      std::vector<Eigen::Vector2d> footprint;
      for (auto c : {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1), Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1)})
        footprint.push_back(b.centre + rot * c.cwiseProduct(b.size / 2));
      check_off_carriageway(footprint, b.where, "building", world.sidewalks, "road or its sidewalks");
      const float base = world.raised_level(b.centre);
      add_box(world.mesh, b.centre.cast<float>(), (b.size / 2).cast<float>(), float(b.yaw), base - 0.3f,
              base + float(b.height), m);
    }
  }

  void build_objects() {
    build_buildings();
    const MaterialId metal = mat("metal"), sign = mat("retro_reflector"), leaves = mat("vegetation");
    const region::Paths near_carriageway = region::offset(world.carriageway, 0.5);
    // Street furniture stands closer to the curb than poles and trees: clear of the road by this.
    const region::Paths near_for_furniture = region::offset(world.carriageway, kFurnitureClearance);
    // Where a row puts its objects (and, if asked, the foot of each on the curb line).
    auto row_positions = [&](const RowSpec& row, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& out,
                             const region::Paths& keep_out, std::vector<Eigen::Vector2d>* feet) {
      const RoadSpec& road = *desc.road(row.road);
      const double len = polyline_length(road.centreline);
      for (double s = row.start; s <= len; s += row.spacing) {
        const PolylineSample at = sample_polyline(road.centreline, s);
        for (double side : {1.0, -1.0}) {
          if ((side > 0 && row.side == RoadSide::right) || (side < 0 && row.side == RoadSide::left)) continue;
          const Eigen::Vector2d p = at.point + left_normal(at.tangent) * side * (road.width / 2 + row.setback);
          // Rows run through intersections; skip the positions that fall on a carriageway.
          if (region::contains(keep_out, p)) continue;
          out.emplace_back(p, at.tangent);
          if (feet) feet->push_back(at.point + left_normal(at.tangent) * side * (road.width / 2));
        }
      }
    };
    for (const auto& row : desc.poles) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots, near_carriageway, nullptr);
      for (const auto& [p, t] : spots) {
        const float base = world.raised_level(p);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base}, 0.08f, 0.06f, float(row.height), 12, metal);
        if (row.sign)
          add_box(world.mesh, p.cast<float>(), {0.02f, 0.35f}, float(std::atan2(t.y(), t.x())),
                  base + float(row.height) - 1.2f, base + float(row.height) - 0.5f, sign);
      }
    }
    for (const auto& row : desc.trees) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots, near_carriageway, nullptr);
      for (const auto& [p, t] : spots) {
        add_tree(world.mesh, {float(p.x()), float(p.y()), world.raised_level(p)}, float(row.height),
                 float(row.crown_radius), leaves);
      }
    }
    // Street furniture by the curb: bollards (steel) and hydrants (painted iron, a cap on top), not in
    // front of a cut or on its flares (where the curb is lowered, within its radius along the curb).
    const MaterialId painted = mat("vehicle_paint");
    const LoweredCurb lowered_curb(*world.curb_band);
    auto furniture_spots = [&](const RowSpec& row, double radius) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots, kept;
      std::vector<Eigen::Vector2d> feet;
      row_positions(row, spots, near_for_furniture, &feet);
      for (size_t k = 0; k < spots.size(); ++k)
        if (!lowered_curb.near(feet[k], radius + kCurbStation)) kept.push_back(spots[k]);
      return kept;
    };
    for (const auto& row : desc.bollards)
      for (const auto& [p, t] : furniture_spots(row, row.diameter / 2))
        add_frustum(world.mesh, {float(p.x()), float(p.y()), world.raised_level(p)}, float(row.diameter / 2),
                    float(row.diameter / 2), float(row.height), 10, metal);
    for (const auto& row : desc.hydrants)
      for (const auto& [p, t] : furniture_spots(row, row.diameter / 2)) {
        const float base = world.raised_level(p), r = float(row.diameter / 2), body = float(row.height) * kHydrantBody;
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base}, r, r, body, 10, painted);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + body}, r, r * kHydrantCapTop,
                    float(row.height) - body, 10, painted);
      }
    build_hedges(leaves);
    build_verges();
    // Construction zones (a scenario's world_changes): cones along the closed side's inner edge, with
    // a retro-reflective band, and concrete barriers down the middle of the closed lanes.
    const MaterialId cone = mat("traffic_cone"), concrete = mat("curb_concrete");
    for (const auto& zone : desc.construction) {
      const RoadSpec& road = *desc.road(zone.road);
      const double side = zone.side == RoadSide::left ? 1.0 : -1.0;
      const Polyline2d stretch = stretch_of(road.centreline, zone.at, zone.length);
      const double length = polyline_length(stretch), lane_middle = side * road.width / 4;
      for (double s = 0; s <= length; s += kConeSpacing) {
        const PolylineSample at = sample_polyline(stretch, s);
        const Eigen::Vector2d p = at.point + left_normal(at.tangent) * side * kConeInset;
        const float base = float(world.surface->carriageway(p));
        const Eigen::Vector3f foot(float(p.x()), float(p.y()), base);
        add_frustum(world.mesh, foot, kConeBaseRadius, kConeTopRadius, kConeHeight, 8, cone);
        add_frustum(world.mesh, foot + Eigen::Vector3f(0, 0, kBandLow), kBandRadiusLow, kBandRadiusHigh,
                    kBandHigh - kBandLow, 8, sign);
      }
      for (double s = kBarrierLength / 2; s + kBarrierLength / 2 <= length; s += kBarrierLength) {
        const PolylineSample at = sample_polyline(stretch, s);
        const Eigen::Vector2d p = at.point + left_normal(at.tangent) * lane_middle;
        const float base = float(world.surface->carriageway(p));
        add_box(world.mesh, p.cast<float>(), {float(kBarrierLength / 2 - kBarrierJoint), kBarrierHalfWidth},
                float(std::atan2(at.tangent.y(), at.tangent.x())), base, base + kBarrierHeight, concrete);
      }
      if (zone.curb_shift > 0) {
        // The temporary kerb: its road-side face is the new curb line, `curb_shift` in from the old one.
        const double face = road.width / 2 - zone.curb_shift;
        Polyline2d line;
        for (double s = 0; s < length; s += kKerbBlockLength) {
          const double mid = std::min(s + kKerbBlockLength / 2, length);
          const PolylineSample at = sample_polyline(stretch, mid);
          const Eigen::Vector2d p = at.point + left_normal(at.tangent) * side * (face + kKerbHalfWidth);
          const float base = float(world.surface->carriageway(p));
          add_box(world.mesh, p.cast<float>(), {float(kKerbBlockLength / 2), kKerbHalfWidth},
                  float(std::atan2(at.tangent.y(), at.tangent.x())), base, base + float(road.curb_height), concrete);
        }
        for (double s = 0;; s = std::min(s + kKerbBlockLength, length)) {
          const PolylineSample at = sample_polyline(stretch, s);
          line.push_back(at.point + left_normal(at.tangent) * side * face);
          if (s >= length) break;
        }
        world.curbs.push_back(line);
        world.curb_kinds.push_back(curb_profile_name(CurbProfile::vertical));
      }
    }
    build_parked();
  }

  void build_parked() {
    std::map<std::string, TriangleMesh> meshes;
    for (const auto& v : desc.parked) {
      if (!meshes.count(v.type)) meshes[v.type] = load_actor_mesh(actors_dir, *actor_type_from_name(v.type), materials);
      const TriangleMesh& mesh = meshes[v.type];
      Eigen::AlignedBox3f box;
      for (const auto& p : mesh.vertices) box.extend(p);
      const Eigen::Rotation2D<double> rot(v.yaw);
      std::vector<Eigen::Vector2d> footprint;
      for (auto c : {Eigen::Vector2d(box.min().x(), box.min().y()), Eigen::Vector2d(box.max().x(), box.min().y()),
                     Eigen::Vector2d(box.max().x(), box.max().y()), Eigen::Vector2d(box.min().x(), box.max().y())})
        footprint.push_back(v.position + rot * c);
      check_off_carriageway(footprint, v.where, "parked " + v.type, world.carriageway, "carriageway");
      Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
      pose.translate(Eigen::Vector3f(float(v.position.x()), float(v.position.y()), world.raised_level(v.position)));
      pose.rotate(Eigen::AngleAxisf(float(v.yaw), Eigen::Vector3f::UnitZ()));
      world.mesh.append(mesh, pose);
    }
  }
};

}  // namespace

GroundHeight World::ground() const {
  auto area = std::make_shared<const region::ContainsIndex>(carriageway);
  return [area, surface = surface, raised = raised_level](const Eigen::Vector2d& p) {
    return area->contains(p) ? surface->carriageway(p) : double(raised(p));
  };
}

GroundHeight World::pavement() const {
  return [surface = surface](const Eigen::Vector2d& p) { return surface->carriageway(p); };
}

World build_world(const WorldDescription& description, const MaterialTable& materials, const std::string& actors_dir) {
  Builder b{description, materials, actors_dir, {}, {}};
  if (description.opendrive) {  // as a Lanelet2 map's below
    OdrBuildReport report;
    OdrWorldParams params = description.opendrive->params;
    params.paint = description.paint;
    b.world = build_opendrive_world(description.opendrive->map, params, materials, actors_dir, &report);
    b.world.name = description.name;
    b.world.import_report = report.summary();
    b.build_buildings();
    b.build_parked();
    return std::move(b.world);
  }
  if (description.lanelet2) {
    // The road network is the map's; what the world file adds stands on it.
    Lanelet2BuildReport report;
    Lanelet2WorldParams params = description.lanelet2->params;
    params.paint = description.paint;
    b.world = build_lanelet2_world(description.lanelet2->map, params, materials, actors_dir, &report);
    b.world.name = description.name;
    b.world.import_report = report.summary();
    b.build_buildings();
    b.build_parked();
    return std::move(b.world);
  }
  b.world.name = description.name;
  b.world.origin = description.origin;
  b.world.surface = std::make_shared<const RoadSurface>(description);
  b.build_regions();
  b.build_ground();
  b.build_markings();
  b.build_objects();
  b.world.paint_materials = b.painter.variants();
  return std::move(b.world);
}

}  // namespace lidarloop
