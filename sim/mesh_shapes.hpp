#pragma once
// Mesh helpers shared by the world generators (sim/world_builder.cpp, sim/lanelet2_world.cpp): paint
// draped over the ground, dashed lines, trees. Moved here unchanged from world_builder.cpp so both
// build the same shapes.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "common/curb_map_file.hpp"  // Polyline2d
#include "sim/paint_wear.hpp"
#include "sim/triangle_mesh.hpp"

namespace lidarloop {

constexpr double kPaintPiece = 0.5;  // m; paint is draped over the pavement in pieces this long

// A quad of paint (or grass) draped `height` above the ground: split along its length into pieces,
// each corner at the ground's height there. With `painter`, pieces it finds worn are left out (the
// asphalt beneath shows); `fresh` paint has none.
template <class Ground>
void add_paint_quad(TriangleMesh& mesh, const Eigen::Vector2d& centre, const Eigen::Vector2d& along, double half_length,
                    double half_width, const Ground& ground, double height, MaterialId m,
                    const MarkingPainter* painter = nullptr, bool fresh = false) {
  const Eigen::Vector2d u = along.normalized(), v(-u.y(), u.x());
  const int pieces = std::max(1, int(std::ceil(2 * half_length / kPaintPiece)));
  const auto base = static_cast<uint32_t>(mesh.vertices.size());
  for (int k = 0; k <= pieces; ++k)
    for (double side : {-1.0, 1.0}) {
      const Eigen::Vector2d p = centre + u * (half_length * (2.0 * k / pieces - 1)) + v * (side * half_width);
      mesh.vertices.emplace_back(float(p.x()), float(p.y()), float(ground(p) + height));
    }
  for (uint32_t k = 0; k < uint32_t(pieces); ++k) {  // vertices 2k (right), 2k + 1 (left)
    if (painter && painter->worn(centre + u * (half_length * ((2.0 * k + 1) / pieces - 1)), fresh)) continue;
    mesh.add_triangle(base + 2 * k, base + 2 * k + 2, base + 2 * k + 3, m);
    mesh.add_triangle(base + 2 * k, base + 2 * k + 3, base + 2 * k + 1, m);
  }
}

// One marking laid as a quad (a crosswalk bar): its material drawn by `painter` (sim/paint_wear.hpp),
// keyed by its centre, and its worn pieces left out.
template <class Ground>
void add_marking_quad(TriangleMesh& mesh, const Eigen::Vector2d& centre, const Eigen::Vector2d& along,
                      double half_length, double half_width, const Ground& ground, double height, MaterialId m,
                      MarkingPainter& painter) {
  bool fresh = false;
  const MaterialId look = painter.marking(m, marking_key(centre), fresh);
  add_paint_quad(mesh, centre, along, half_length, half_width, ground, height, look, &painter, fresh);
}

// A strip of paint along a polyline. With `painter`, the line is a marking (a dash, a stop line, a
// solid line) whose every `segment_m` from its start is drawn on its own, keyed by the line's first
// point and the stretch's index.
template <class Ground>
void add_paint_line(TriangleMesh& mesh, const Polyline2d& line, double half_width, const Ground& ground, double height,
                    MaterialId m, MarkingPainter* painter = nullptr) {
  double s = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d d = line[i] - line[i - 1];
    const double length = d.norm();
    s += length;
    if (length < 1e-4) continue;
    if (!painter || painter->uniform()) {
      add_paint_quad(mesh, 0.5 * (line[i] + line[i - 1]), d, 0.5 * length, half_width, ground, height, m);
      continue;
    }
    // Cut at the stretches' ends, so that each stretch's paint is its own draw however long the
    // polyline's segments are.
    const double seg = painter->segment_m(), start = s - length;
    for (auto k = uint64_t(start / seg + 1e-9); double(k) * seg < s - 1e-9; ++k) {
      const double from = std::max(start, double(k) * seg), to = std::min(s, double(k + 1) * seg);
      if (to - from < 1e-4) continue;
      const Eigen::Vector2d a = line[i - 1] + d * ((from - start) / length),
                            b = line[i - 1] + d * ((to - start) / length);
      bool fresh = false;
      const MaterialId look = painter->marking(m, marking_key(line.front(), k), fresh);
      add_paint_quad(mesh, 0.5 * (a + b), d, 0.5 * (to - from), half_width, ground, height, look, painter, fresh);
    }
  }
}

// Splits a line into dashes of `dash` metres separated by `gap` metres.
std::vector<Polyline2d> dashes(const Polyline2d& line, double dash, double gap);

// A tree standing at `base`: a trunk and a crown of two frustums, `height` tall, `crown_radius` wide.
void add_tree(TriangleMesh& mesh, const Eigen::Vector3f& base, float height, float crown_radius, MaterialId material);

}  // namespace lidarloop
