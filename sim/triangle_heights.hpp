#pragma once
// Heights of a surface given as triangles (an OpenDRIVE map's lanes, each sampled along its road):
// the height at a point is interpolated in the triangle under it, so the ground a wheel or a scan
// meets is the lanes' own analytic surface, not a blend.
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

class TriangleHeights {
 public:
  explicit TriangleHeights(double cell = 2.0) : cell_(cell) {}
  void add_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
  // The two triangles a-b-c, a-c-d of a quad.
  void add_quad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d);
  bool empty() const { return triangles_.empty(); }

  // The height of the highest triangle over p (overlapping roads in junctions: the top one), a
  // millimetre's tolerance round each triangle's edges; nothing off the surface.
  std::optional<double> at(const Eigen::Vector2d& p) const;
  // As at(), else the height of the nearest corner within the neighbouring cells (a point just off a
  // lane's edge, in a sliver the carriageway's closing filled).
  std::optional<double> near(const Eigen::Vector2d& p) const;

 private:
  struct Triangle {
    Eigen::Vector3d a, b, c;
  };
  int64_t key(int64_t i, int64_t j) const { return (i << 32) ^ (j & 0xffffffff); }
  double cell_;
  std::vector<Triangle> triangles_;
  std::unordered_map<int64_t, std::vector<uint32_t>> cells_;
};

}  // namespace lidarloop
