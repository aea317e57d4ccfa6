#include "sim/mesh_shapes.hpp"

#include "sim/polyline.hpp"

namespace lidarloop {

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

void add_tree(TriangleMesh& mesh, const Eigen::Vector3f& base, float height, float crown_radius, MaterialId material) {
  const float h = height, r = crown_radius;
  add_frustum(mesh, base, 0.15f, 0.12f, 0.45f * h, 8, material);
  add_frustum(mesh, base + Eigen::Vector3f(0, 0, 0.35f * h), 0.3f, r, 0.3f * h, 10, material);
  add_frustum(mesh, base + Eigen::Vector3f(0, 0, 0.65f * h), r, 0.3f, 0.35f * h, 10, material);
}

}  // namespace lidarloop
