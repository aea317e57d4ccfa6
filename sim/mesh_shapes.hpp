#pragma once
// Mesh helpers shared by the world generators (sim/world_builder.cpp, sim/lanelet2_world.cpp): paint
// draped over the ground, dashed lines, trees. Moved here unchanged from world_builder.cpp so both
// build the same shapes.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "common/curb_map_file.hpp"  // Polyline2d
#include "sim/triangle_mesh.hpp"

namespace lidarloop {

constexpr double kPaintPiece = 0.5;  // m; paint is draped over the pavement in pieces this long

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
std::vector<Polyline2d> dashes(const Polyline2d& line, double dash, double gap);

// A tree standing at `base`: a trunk and a crown of two frustums, `height` tall, `crown_radius` wide.
void add_tree(TriangleMesh& mesh, const Eigen::Vector3f& base, float height, float crown_radius, MaterialId material);

}  // namespace lidarloop
