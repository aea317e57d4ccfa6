#include "sim/world_builder.hpp"

#include <cmath>
#include <map>
#include <memory>

#include <nanoflann.hpp>

#include "common/input_error.hpp"
#include "sim/actor_assets.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kGroundTile = 8.0;       // m; ground triangles are at most this size near edges
constexpr double kIntersectionPad = 2.0;  // m beyond the corner radius where lane paint stops
constexpr double kCrosswalkPad = 1.0;     // m before a crosswalk where lane paint stops

// Height of the raised ground (curb tops, sidewalks, verges): the curb height of the nearest road.
// Copies share the samples and their KD-tree, so it can live in a std::function.
class RaisedLevel {
 public:
  explicit RaisedLevel(const std::vector<RoadSpec>& roads) : constant_(float(roads.front().curb_height)) {
    bool uniform = true;
    for (const auto& r : roads) uniform = uniform && r.curb_height == roads.front().curb_height;
    if (uniform) return;
    samples_ = std::make_shared<Samples>();
    for (const auto& r : roads) {
      const double len = polyline_length(r.centreline);
      for (double s = 0; s <= len; s += 1.0) {
        samples_->points.push_back(sample_polyline(r.centreline, s).point);
        samples_->heights.push_back(float(r.curb_height));
      }
    }
    index_ = std::make_shared<Index>(2, *samples_, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    index_->buildIndex();
  }
  float operator()(const Eigen::Vector2d& p) const {
    if (!index_) return constant_;
    uint32_t nearest = 0;
    double dist2 = 0;
    index_->knnSearch(p.data(), 1, &nearest, &dist2);
    return samples_->heights[nearest];
  }

 private:
  struct Samples {  // nanoflann dataset interface
    std::vector<Eigen::Vector2d> points;
    std::vector<float> heights;
    size_t kdtree_get_point_count() const { return points.size(); }
    double kdtree_get_pt(size_t i, size_t dim) const { return points[i][int(dim)]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Samples>, Samples, 2>;
  float constant_;
  std::shared_ptr<Samples> samples_;
  std::shared_ptr<Index> index_;
};

Eigen::Vector2d left_normal(const Eigen::Vector2d& tangent) { return {-tangent.y(), tangent.x()}; }

// A quad strip of paint along a polyline.
void add_paint_line(TriangleMesh& mesh, const Polyline2d& line, double half_width, float z, MaterialId m) {
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d d = line[i] - line[i - 1];
    if (d.norm() < 1e-4) continue;
    const Eigen::Vector2f c = (0.5 * (line[i] + line[i - 1])).cast<float>();
    const Eigen::Vector2f u = (d / d.norm()).cast<float>();
    const Eigen::Vector2f v(-u.y(), u.x());
    const float hl = float(0.5 * d.norm()), hw = float(half_width);
    add_flat_quad(mesh, {c - u * hl - v * hw, c + u * hl - v * hw, c + u * hl + v * hw, c - u * hl + v * hw}, z, m);
  }
}

// Splits a line into dashes of `dash` metres separated by `gap` metres.
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
    world.sidewalks = region::unite(region::closing(sidewalk_union, r),
                                    region::offset(world.carriageway, desc.geometry.curb_top_width));
    // Where two roads overlap is an intersection: no lane paint there or around its rounded corners.
    for (size_t i = 0; i < strips.size(); ++i)
      for (size_t j = i + 1; j < strips.size(); ++j) {
        const region::Paths overlap = region::intersect(strips[i], strips[j]);
        if (!overlap.empty())
          no_lane_paint = region::unite(no_lane_paint, region::offset(overlap, r + kIntersectionPad));
      }
    for (const auto& c : world.carriageway) world.curbs.push_back(region::to_polyline(c, true));
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
    Eigen::AlignedBox2d box;
    for (const auto& path : world.sidewalks)
      for (const auto& p : region::to_polyline(path, false)) box.extend(p);
    for (const auto& b : desc.buildings) box.extend(b.centre + Eigen::Vector2d::Constant(b.size.norm()));
    for (const auto& b : desc.buildings) box.extend(b.centre - Eigen::Vector2d::Constant(b.size.norm()));
    box.min() -= Eigen::Vector2d::Constant(g.margin);
    box.max() += Eigen::Vector2d::Constant(g.margin);
    world.bounds = box;

    const region::Paths curb_tops =
        region::subtract(region::offset(world.carriageway, g.curb_top_width), world.carriageway);
    const region::Paths sidewalk = region::subtract(
        world.sidewalks, region::unite(world.carriageway, region::offset(world.carriageway, g.curb_top_width)));
    const region::Paths verge = region::subtract(
        region::rectangle(box.center(), {1, 0}, box.sizes().x() / 2, box.sizes().y() / 2), world.sidewalks);
    auto flat = [](const Eigen::Vector2d&) { return 0.0f; };
    region::mesh_region(world.carriageway, kGroundTile, flat, mat("asphalt"), world.mesh);
    region::mesh_region(curb_tops, kGroundTile, world.raised_level, mat("curb_concrete"), world.mesh);
    region::mesh_region(sidewalk, kGroundTile, world.raised_level, mat("sidewalk"), world.mesh);
    region::mesh_region(verge, kGroundTile, world.raised_level, mat("grass"), world.mesh);

    // Curb faces: vertical quads from the asphalt up to the raised level, facing the carriageway
    // (Clipper keeps the filled side on the left of every ring, outer or hole).
    const MaterialId curb = mat("curb_concrete");
    for (const auto& ring : world.curbs)
      for (size_t i = 1; i < ring.size(); ++i) {
        const Eigen::Vector2f a = ring[i - 1].cast<float>(), b = ring[i].cast<float>();
        const auto base = static_cast<uint32_t>(world.mesh.vertices.size());
        world.mesh.vertices.insert(world.mesh.vertices.end(), {{a.x(), a.y(), 0.0f},
                                                               {b.x(), b.y(), 0.0f},
                                                               {b.x(), b.y(), world.raised_level(ring[i])},
                                                               {a.x(), a.y(), world.raised_level(ring[i - 1])}});
        world.mesh.add_triangle(base + 1, base, base + 3, curb);
        world.mesh.add_triangle(base + 1, base + 3, base + 2, curb);
      }
  }

  void build_markings() {
    const auto& g = desc.geometry;
    const float z = static_cast<float>(g.paint_height);
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
        const Polyline2d rect =
            region::to_polyline(region::rectangle(centre, s.tangent, c.width / 2, g.crosswalk_stripe / 2)[0], false);
        add_flat_quad(world.mesh,
                      {rect[0].cast<float>(), rect[1].cast<float>(), rect[2].cast<float>(), rect[3].cast<float>()}, z,
                      zebra);
      }
    }
    for (const auto& sl : desc.stop_lines) {
      const RoadSpec& road = *desc.road(sl.road);
      const PolylineSample s = sample_polyline(road.centreline, sl.at);
      const Eigen::Vector2d n = left_normal(s.tangent);
      const double lo = sl.side == RoadSide::left ? 0.0 : -road.width / 2 + g.edge_line_inset;
      const double hi = sl.side == RoadSide::right ? 0.0 : road.width / 2 - g.edge_line_inset;
      add_paint_line(world.mesh, {s.point + n * lo, s.point + n * hi}, g.stop_line_width / 2, z, lane);
    }
    for (const auto& road : desc.roads) {
      std::vector<Polyline2d> solid, dashed;
      auto& dividers = road.marking == MarkingStyle::solid ? solid : dashed;
      if (road.marking != MarkingStyle::none)
        for (int k = 1; k < road.lanes; ++k)
          dividers.push_back(
              offset_polyline(road.centreline, -road.width / 2 + k * road.width / road.lanes, road.closed));
      if (road.edge_lines)
        for (double side : {-1.0, 1.0})
          solid.push_back(offset_polyline(road.centreline, side * (road.width / 2 - g.edge_line_inset), road.closed));
      for (const auto& line : region::clip_lines_outside(solid, no_lane_paint))
        add_paint_line(world.mesh, line, g.paint_width / 2, z, lane);
      for (const auto& line : region::clip_lines_outside(dashed, no_lane_paint))
        for (const auto& dash : dashes(line, g.dash_length, g.dash_gap))
          add_paint_line(world.mesh, dash, g.paint_width / 2, z, lane);
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
    auto row_positions = [&](const RowSpec& row, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& out) {
      const RoadSpec& road = *desc.road(row.road);
      const double len = polyline_length(road.centreline);
      for (double s = row.start; s <= len; s += row.spacing) {
        const PolylineSample at = sample_polyline(road.centreline, s);
        for (double side : {1.0, -1.0}) {
          if ((side > 0 && row.side == RoadSide::right) || (side < 0 && row.side == RoadSide::left)) continue;
          const Eigen::Vector2d p = at.point + left_normal(at.tangent) * side * (road.width / 2 + row.setback);
          // Rows run through intersections; skip the positions that fall on a carriageway.
          if (region::contains(near_carriageway, p)) continue;
          out.emplace_back(p, at.tangent);
        }
      }
    };
    for (const auto& row : desc.poles) {
      std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> spots;
      row_positions(row, spots);
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
      row_positions(row, spots);
      for (const auto& [p, t] : spots) {
        const float base = world.raised_level(p), h = float(row.height), r = float(row.crown_radius);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base}, 0.15f, 0.12f, 0.45f * h, 8, leaves);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + 0.35f * h}, 0.3f, r, 0.3f * h, 10, leaves);
        add_frustum(world.mesh, {float(p.x()), float(p.y()), base + 0.65f * h}, r, 0.3f, 0.35f * h, 10, leaves);
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

World build_world(const WorldDescription& description, const MaterialTable& materials, const std::string& actors_dir) {
  Builder b{description, materials, actors_dir, {}, {}};
  b.world.name = description.name;
  b.world.origin = description.origin;
  b.world.raised_level = RaisedLevel(description.roads);
  b.build_regions();
  b.build_ground();
  b.build_markings();
  b.build_objects();
  return std::move(b.world);
}

}  // namespace lidarloop
