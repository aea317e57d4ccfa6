#pragma once
// Planar regions (polygons with holes) for the world generator, on top of Clipper's exact integer
// arithmetic: offsets, boolean operations, morphological closing, and meshing into triangles.
#include <functional>

#include <polyclipping/clipper.hpp>

#include "common/curb_map_file.hpp"  // Polyline2d
#include "sim/triangle_mesh.hpp"

namespace lidarloop::region {

using Paths = ClipperLib::Paths;

// Clipper works on integers: 1 unit = 0.1 mm, far below anything a LiDAR resolves.
constexpr double kScale = 1e4;

ClipperLib::Path to_path(const Polyline2d& line);
Polyline2d to_polyline(const ClipperLib::Path& path, bool repeat_first);

// The area within half_width of a centreline (butt ends; a closed line gives a ring).
Paths strip(const Polyline2d& centreline, double half_width, bool closed_line);
Paths rectangle(const Eigen::Vector2d& centre, const Eigen::Vector2d& axis, double half_length, double half_width);
Paths offset(const Paths& region, double delta);  // grow (delta > 0) or shrink, round joins
Paths unite(const Paths& a, const Paths& b);
Paths subtract(const Paths& a, const Paths& b);
Paths intersect(const Paths& a, const Paths& b);
// Morphological closing: fills concave corners tighter than `radius` with circular arcs.
Paths closing(const Paths& region, double radius);
// Parts of open polylines outside `region`.
std::vector<Polyline2d> clip_lines_outside(const std::vector<Polyline2d>& lines, const Paths& region);

bool contains(const Paths& region, const Eigen::Vector2d& p);
double area(const Paths& region);

// contains() for a region asked many times (the ground under each walking actor at every keyframe of
// every scan): the same answer, bit for bit, from only the edges that reach the point's horizontal
// band instead of every edge of the region. The point-in-polygon test is Clipper's (Hormann and
// Agathos 2001), which an edge whose y-range misses the point's y never affects.
class ContainsIndex {
 public:
  explicit ContainsIndex(const Paths& region, double band_m = 1.0);
  bool contains(const Eigen::Vector2d& p) const;

 private:
  struct Edge {
    ClipperLib::IntPoint a, b;
    int path;
  };
  std::vector<int> path_sign_;  // +1 for an outer path, -1 for a hole (Clipper's orientation)
  ClipperLib::cInt y0_ = 0, band_ = 1;
  std::vector<std::vector<Edge>> bands_;  // each band's edges, grouped by path
};

// Triangulates a region as a surface whose height is given per vertex, by a quadtree on a global grid
// (so neighbouring regions share tile edges): squares wholly inside the region become two triangles
// each at most `max_square` wide (so a curved surface is sampled that densely); squares the region's
// edge crosses are split down to `tile_size`, and further while a piece has a hole, so every piece
// ear-clipped is a small simple polygon.
void mesh_region(const Paths& region, double tile_size, const std::function<float(const Eigen::Vector2d&)>& height,
                 MaterialId material, TriangleMesh& mesh, double max_square = 1e9);

// Ear-clipping triangulation of a simple polygon; returns index triples into `polygon`.
std::vector<std::array<uint32_t, 3>> triangulate_polygon(const ClipperLib::Path& polygon);

}  // namespace lidarloop::region
