#include "sim/world_builder.hpp"

#include <cmath>
#include <map>
#include <memory>

#include "common/input_error.hpp"
#include "sim/actor_assets.hpp"
#include "sim/curb_band.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kGroundTile = 8.0;       // m; verge triangles are at most this size near edges
constexpr double kVergeSquare = 4.0;      // m; verge squares sample the terrain's hills this densely
constexpr double kRoadTile = 0.5;         // m; pavement and sidewalks: crown, roughness, ramps
constexpr double kCurbStation = 0.5;      // m between cross-sections of the curb band
constexpr double kPaintPiece = 0.5;       // m; paint is draped over the pavement in pieces this long
constexpr double kIntersectionPad = 2.0;  // m beyond the corner radius where lane paint stops
constexpr double kCrosswalkPad = 1.0;     // m before a crosswalk where lane paint stops
// Work zones. Cones: MUTCD (2009) 6F.64, at least 28 in (0.71 m) tall, with a retro-reflective band for
// night use; spaced in feet at about the speed in mph (6C.08: 30 km/h ~ 20 mph ~ 6 m), 0.3 m inside
// the closed side. Barriers: the New Jersey / F-shape concrete safety barrier, 32 in (0.81 m) tall,
// 24 in (0.61 m) at its base, in 12.5 ft (3.8 m) segments.
constexpr double kConeSpacing = 6.0, kConeInset = 0.3;                                                   // m
constexpr float kConeHeight = 0.71f, kConeBaseRadius = 0.18f, kConeTopRadius = 0.03f;                    // m
constexpr float kBandLow = 0.40f, kBandHigh = 0.55f, kBandRadiusLow = 0.105f, kBandRadiusHigh = 0.075f;  // m
constexpr double kBarrierLength = 3.8, kBarrierJoint = 0.05;         // m; a barrier segment and half the gap between
constexpr float kBarrierHeight = 0.81f, kBarrierHalfWidth = 0.305f;  // m

// Roadside: hedges are meshed in pieces this long; a hydrant's barrel is this share of its height,
// its cap narrows to this share of its radius; a verge starts just behind the curb's top and lies a
// little above the raised ground, so the two do not fight for the same rays.
constexpr double kHedgePiece = 1.0;                           // m
constexpr float kHydrantBody = 0.8f, kHydrantCapTop = 0.5f;   // -
constexpr double kVergeFromCurbTop = 0.3, kVergeLift = 0.01;  // m
constexpr double kFurnitureClearance = 0.2;                   // m from the carriageway to a post's axis

Eigen::Vector2d left_normal(const Eigen::Vector2d& tangent) { return {-tangent.y(), tangent.x()}; }

// A quad of paint (or grass) draped `height` above the ground: split along its length into pieces,
// each corner at the ground's height there.
template <class Ground>
void add_paint_quad(TriangleMesh& mesh, const Eigen::Vector2d& centre, const Eigen::Vector2d& along, double half_length,
                    double half_width, const Ground& ground, double height, MaterialId m) {
  const Eigen::Vector2d u = along.normalized(), v(-u.y(), u.x());
  const int pieces = std::max(1, int(std::ceil(2 * half_length / kPaintPiece)));
  const auto base = static_cast<uint32_t>(mesh.vertices.size());
  for (int k = 0; k <= pieces; ++k)
    for (double side : {-1.0, 1.0}) {
      const Eigen::Vector2d p = centre + u * (half_length * (2.0 * k / pieces - 1)) + v * (side * half_width);
      mesh.vertices.emplace_back(float(p.x()), float(p.y()), float(ground(p) + height));
    }
  for (uint32_t k = 0; k < uint32_t(pieces); ++k) {  // vertices 2k (right), 2k + 1 (left)
    mesh.add_triangle(base + 2 * k, base + 2 * k + 2, base + 2 * k + 3, m);
    mesh.add_triangle(base + 2 * k, base + 2 * k + 3, base + 2 * k + 1, m);
  }
}

// A strip of paint along a polyline.
template <class Ground>
void add_paint_line(TriangleMesh& mesh, const Polyline2d& line, double half_width, const Ground& ground, double height,
                    MaterialId m) {
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d d = line[i] - line[i - 1];
    if (d.norm() < 1e-4) continue;
    add_paint_quad(mesh, 0.5 * (line[i] + line[i - 1]), d, 0.5 * d.norm(), half_width, ground, height, m);
  }
}

// Splits a line into dashes of `dash` metres separated by `gap` metres.
// The part of a centreline within length/2 of arc length `at`, sampled every kPaintPiece.
Polyline2d stretch_of(const Polyline2d& centreline, double at, double length) {
  const double from = std::max(0.0, at - length / 2), to = std::min(polyline_length(centreline), at + length / 2);
  Polyline2d out;
  const int pieces = std::max(1, int(std::ceil((to - from) / kPaintPiece)));
  for (int k = 0; k <= pieces; ++k) out.push_back(sample_polyline(centreline, from + (to - from) * k / pieces).point);
  return out;
}

std::vector<Polyline2d> dashes(const Polyline2d& line, double dash, double gap) {
  std::vector<Polyline2d> out;
  const double len = polyline_length(line);
  for (double s = 0; s < len; s += dash + gap) {
    Polyline2d piece;
    const double end = std::min(len, s + dash);
    piece.push_back(sample_polyline(line, s).point);
    double acc = 0;
    for (size_t i = 1; i < line.size(); ++i) {
      acc += (line[i] - line[i - 1]).norm();
      if (acc > s && acc < end) piece.push_back(line[i]);
    }
    piece.push_back(sample_polyline(line, end).point);
    if (end - s > 0.05) out.push_back(std::move(piece));
  }
  return out;
}

struct Builder {
  const WorldDescription& desc;
  const MaterialTable& materials;
  const std::string& actors_dir;
  World world;
  region::Paths no_lane_paint;  // intersections and crosswalk approaches

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
        add_paint_quad(world.mesh, centre, s.tangent, c.width / 2, g.crosswalk_stripe / 2, pavement, z, zebra);
      }
    }
    for (const auto& sl : desc.stop_lines) {
      const RoadSpec& road = *desc.road(sl.road);
      const PolylineSample s = sample_polyline(road.centreline, sl.at);
      const Eigen::Vector2d n = left_normal(s.tangent);
      const double inset = g.edge_line_inset + road.gutter_width;
      const double lo = sl.side == RoadSide::left ? 0.0 : -road.width / 2 + inset;
      const double hi = sl.side == RoadSide::right ? 0.0 : road.width / 2 - inset;
      add_paint_line(world.mesh, {s.point + n * lo, s.point + n * hi}, g.stop_line_width / 2, pavement, z, lane);
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
          for (const auto& piece : pieces) add_paint_line(world.mesh, piece, g.paint_width / 2, pavement, z, lane);
        }
      };
      paint(road.centreline, road.closed, 0, changed);
      for (const auto& c : desc.paint_changes)
        if (c.road == road.name && c.shift != 0) paint(stretch_of(road.centreline, c.at, c.length), false, c.shift, {});
    }
  }

  void build_objects() {
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
    const MaterialId metal = mat("metal"), sign = mat("retro_reflector"), leaves = mat("vegetation");
    const region::Paths near_carriageway = region::offset(world.carriageway, 0.5);
    // Street furniture stands closer to the curb than poles and trees: clear of the road by this.
    const region::Paths near_for_furniture = region::offset(world.carriageway, kFurnitureClearance);
    auto row_positions = [&](const RowSpec& row, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& out,
                             const region::Paths& keep_out) {
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
        }
      }
    };
    for (const auto& row : desc.poles) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots, near_carriageway);
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
      row_positions(row, spots, near_carriageway);
      for (const auto& [p, t] : spots) {
        const float base = world.raised_level(p), h = float(row.height), r = float(row.crown_radius);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base}, 0.15f, 0.12f, 0.45f * h, 8, leaves);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + 0.35f * h}, 0.3f, r, 0.3f * h, 10, leaves);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + 0.65f * h}, r, 0.3f, 0.35f * h, 10, leaves);
      }
    }
    // Street furniture by the curb: bollards (steel) and hydrants (painted iron, a cap on top).
    const MaterialId painted = mat("vehicle_paint");
    for (const auto& row : desc.bollards) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots, near_for_furniture);
      for (const auto& [p, t] : spots)
        add_frustum(world.mesh, {float(p.x()), float(p.y()), world.raised_level(p)}, float(row.diameter / 2),
                    float(row.diameter / 2), float(row.height), 10, metal);
    }
    for (const auto& row : desc.hydrants) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots, near_for_furniture);
      for (const auto& [p, t] : spots) {
        const float base = world.raised_level(p), r = float(row.diameter / 2), body = float(row.height) * kHydrantBody;
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base}, r, r, body, 10, painted);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + body}, r, r * kHydrantCapTop,
                    float(row.height) - body, 10, painted);
      }
    }
    // Hedges: a bank of leaves behind the curb, leaning out over the curb line above its clearance.
    for (const auto& h : desc.hedges) {
      const RoadSpec& road = *desc.road(h.road);
      const Polyline2d stretch = stretch_of(road.centreline, h.at, h.length);
      const double length = polyline_length(stretch);
      for (double side : {1.0, -1.0}) {
        if ((side > 0 && h.side == RoadSide::right) || (side < 0 && h.side == RoadSide::left)) continue;
        for (double s = kHedgePiece / 2; s < length; s += kHedgePiece) {
          const PolylineSample at = sample_polyline(stretch, s);
          const Eigen::Vector2d out = left_normal(at.tangent) * side;
          const float yaw = float(std::atan2(at.tangent.y(), at.tangent.x()));
          const Eigen::Vector2d trunk = at.point + out * (road.width / 2 + h.setback + h.depth / 2);
          if (region::contains(near_carriageway, trunk)) continue;  // a junction crosses the stretch
          const float base = world.raised_level(trunk);
          add_box(world.mesh, trunk.cast<float>(), {float(kHedgePiece / 2), float(h.depth / 2)}, yaw, base,
                  base + float(h.height), leaves);
          // The overhang: from the curb line minus `overhang` to the hedge's face.
          const double inner = road.width / 2 - h.overhang, outer = road.width / 2 + h.setback;
          const Eigen::Vector2d lean = at.point + out * ((inner + outer) / 2);
          add_box(world.mesh, lean.cast<float>(), {float(kHedgePiece / 2), float((outer - inner) / 2)}, yaw,
                  base + float(h.clearance), base + float(h.height), leaves);
        }
      }
    }
    // Grass verges: a strip of grass between the curb and the sidewalk, draped over the raised ground.
    const MaterialId grass = mat("grass");
    const auto raised = [&](const Eigen::Vector2d& p) { return double(world.raised_level(p)); };
    for (const auto& road : desc.roads) {
      if (road.verge_width <= 0) continue;
      const double inner = road.width / 2 + desc.geometry.curb_top_width + kVergeFromCurbTop;
      for (double side : {1.0, -1.0})
        for (const auto& line : region::clip_lines_outside(
                 {offset_polyline(road.centreline, side * (inner + road.verge_width / 2), road.closed)},
                 near_carriageway))
          add_paint_line(world.mesh, line, road.verge_width / 2, raised, kVergeLift, grass);
    }
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
    }
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
  auto area = std::make_shared<const region::Paths>(carriageway);
  return [area, surface = surface, raised = raised_level](const Eigen::Vector2d& p) {
    return region::contains(*area, p) ? surface->carriageway(p) : double(raised(p));
  };
}

GroundHeight World::pavement() const {
  return [surface = surface](const Eigen::Vector2d& p) { return surface->carriageway(p); };
}

World build_world(const WorldDescription& description, const MaterialTable& materials, const std::string& actors_dir) {
  Builder b{description, materials, actors_dir, {}, {}};
  b.world.name = description.name;
  b.world.origin = description.origin;
  b.world.surface = std::make_shared<const RoadSurface>(description);
  b.build_regions();
  b.build_ground();
  b.build_markings();
  b.build_objects();
  return std::move(b.world);
}

}  // namespace lidarloop
