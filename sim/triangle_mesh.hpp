#pragma once
// An indexed triangle mesh with one material per triangle: what the world generator and the actor
// assets produce, and what the Embree scene consumes.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace lidarloop {

using MaterialId = uint16_t;

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<MaterialId> materials;               // one per triangle

  size_t triangle_count() const { return triangles.size(); }
  void add_triangle(uint32_t a, uint32_t b, uint32_t c, MaterialId m);
  void append(const TriangleMesh& other, const Eigen::Isometry3f& pose = Eigen::Isometry3f::Identity());
};

// Solid primitives used for buildings, poles, trees and markings.
// A box given by its 8 corners' footprint (centre, half extents, yaw) between z0 and z1.
void add_box(TriangleMesh& mesh, const Eigen::Vector2f& centre, const Eigen::Vector2f& half_size, float yaw, float z0,
             float z1, MaterialId material);
// A vertical prism (cylinder or frustum) with `sides` faces.
void add_frustum(TriangleMesh& mesh, const Eigen::Vector3f& base, float radius_bottom, float radius_top, float height,
                 int sides, MaterialId material);
// A flat horizontal quad (e.g. paint) with corners counter-clockwise seen from above.
void add_flat_quad(TriangleMesh& mesh, const std::array<Eigen::Vector2f, 4>& corners, float z, MaterialId material);

}  // namespace lidarloop
