#include "sim/triangle_mesh.hpp"

#include <cmath>

namespace lidarloop {

void TriangleMesh::add_triangle(uint32_t a, uint32_t b, uint32_t c, MaterialId m) {
  triangles.push_back({a, b, c});
  materials.push_back(m);
}

void TriangleMesh::append(const TriangleMesh& other, const Eigen::Isometry3f& pose) {
  const auto offset = static_cast<uint32_t>(vertices.size());
  for (const auto& v : other.vertices) vertices.push_back(pose * v);
  for (size_t i = 0; i < other.triangles.size(); ++i) {
    const auto& t = other.triangles[i];
    add_triangle(t[0] + offset, t[1] + offset, t[2] + offset, other.materials[i]);
  }
}

// Adds a closed prism between two horizontal rings of equal size (bottom ring, then top ring).
static void add_prism(TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& bottom,
                      const std::vector<Eigen::Vector3f>& top, MaterialId material) {
  const auto n = static_cast<uint32_t>(bottom.size());
  const auto b0 = static_cast<uint32_t>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), bottom.begin(), bottom.end());
  mesh.vertices.insert(mesh.vertices.end(), top.begin(), top.end());
  const uint32_t t0 = b0 + n;
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    mesh.add_triangle(b0 + i, b0 + j, t0 + j, material);
    mesh.add_triangle(b0 + i, t0 + j, t0 + i, material);
  }
  for (uint32_t i = 1; i + 1 < n; ++i) {
    mesh.add_triangle(t0, t0 + i, t0 + i + 1, material);  // top faces up
    mesh.add_triangle(b0, b0 + i + 1, b0 + i, material);  // bottom faces down
  }
}

void add_box(TriangleMesh& mesh, const Eigen::Vector2f& centre, const Eigen::Vector2f& half_size, float yaw, float z0,
             float z1, MaterialId material) {
  const Eigen::Rotation2D<float> rot(yaw);
  const Eigen::Vector2f corners[4] = {{-half_size.x(), -half_size.y()},
                                      {half_size.x(), -half_size.y()},
                                      {half_size.x(), half_size.y()},
                                      {-half_size.x(), half_size.y()}};
  std::vector<Eigen::Vector3f> bottom, top;
  for (const auto& c : corners) {
    const Eigen::Vector2f p = centre + rot * c;
    bottom.emplace_back(p.x(), p.y(), z0);
    top.emplace_back(p.x(), p.y(), z1);
  }
  add_prism(mesh, bottom, top, material);
}

void add_frustum(TriangleMesh& mesh, const Eigen::Vector3f& base, float radius_bottom, float radius_top, float height,
                 int sides, MaterialId material) {
  std::vector<Eigen::Vector3f> bottom, top;
  for (int i = 0; i < sides; ++i) {
    const float a = 2.0f * float(M_PI) * float(i) / float(sides);
    const Eigen::Vector3f dir(std::cos(a), std::sin(a), 0.0f);
    bottom.push_back(base + radius_bottom * dir);
    top.push_back(base + radius_top * dir + Eigen::Vector3f(0, 0, height));
  }
  add_prism(mesh, bottom, top, material);
}

void add_flat_quad(TriangleMesh& mesh, const std::array<Eigen::Vector2f, 4>& corners, float z, MaterialId material) {
  const auto b = static_cast<uint32_t>(mesh.vertices.size());
  for (const auto& c : corners) mesh.vertices.emplace_back(c.x(), c.y(), z);
  mesh.add_triangle(b, b + 1, b + 2, material);
  mesh.add_triangle(b, b + 2, b + 3, material);
}

}  // namespace lidarloop
