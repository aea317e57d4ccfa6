#include "sim/triangle_heights.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lidarloop {
namespace {

constexpr double kEdgeTolerance = 1e-3;  // m: Clipper rounds region edges to 0.1 mm

// Distance from p to the triangle (0 inside) and the barycentric weights of the nearest point.
double distance_to(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   const Eigen::Vector2d& c, Eigen::Vector3d& weights) {
  const Eigen::Vector2d v0 = b - a, v1 = c - a, v2 = p - a;
  const double den = v0.x() * v1.y() - v1.x() * v0.y();
  if (std::abs(den) < 1e-12) return std::numeric_limits<double>::infinity();
  const double wb = (v2.x() * v1.y() - v1.x() * v2.y()) / den, wc = (v0.x() * v2.y() - v2.x() * v0.y()) / den;
  weights = {1 - wb - wc, wb, wc};
  if (weights.minCoeff() >= 0) return 0;
  // Outside: the nearest point on an edge.
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d pts[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d& q0 = pts[e];
    const Eigen::Vector2d& q1 = pts[(e + 1) % 3];
    const Eigen::Vector2d d = q1 - q0;
    const double t = std::clamp((p - q0).dot(d) / std::max(d.squaredNorm(), 1e-18), 0.0, 1.0);
    const double dist = (q0 + d * t - p).norm();
    if (dist < best) {
      best = dist;
      weights = Eigen::Vector3d::Zero();
      weights[e] = 1 - t;
      weights[(e + 1) % 3] = t;
    }
  }
  return best;
}

}  // namespace

void TriangleHeights::add_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const auto index = static_cast<uint32_t>(triangles_.size());
  triangles_.push_back({a, b, c});
  const double x0 = std::min({a.x(), b.x(), c.x()}) - kEdgeTolerance,
               x1 = std::max({a.x(), b.x(), c.x()}) + kEdgeTolerance;
  const double y0 = std::min({a.y(), b.y(), c.y()}) - kEdgeTolerance,
               y1 = std::max({a.y(), b.y(), c.y()}) + kEdgeTolerance;
  for (auto i = int64_t(std::floor(x0 / cell_)); i <= int64_t(std::floor(x1 / cell_)); ++i)
    for (auto j = int64_t(std::floor(y0 / cell_)); j <= int64_t(std::floor(y1 / cell_)); ++j)
      cells_[key(i, j)].push_back(index);
}

void TriangleHeights::add_quad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                               const Eigen::Vector3d& d) {
  add_triangle(a, b, c);
  add_triangle(a, c, d);
}

std::optional<double> TriangleHeights::at(const Eigen::Vector2d& p) const {
  const auto it = cells_.find(key(int64_t(std::floor(p.x() / cell_)), int64_t(std::floor(p.y() / cell_))));
  if (it == cells_.end()) return std::nullopt;
  std::optional<double> top;
  for (const uint32_t k : it->second) {
    const Triangle& t = triangles_[k];
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    if (distance_to(p, t.a.head<2>(), t.b.head<2>(), t.c.head<2>(), w) > kEdgeTolerance) continue;
    const double z = w[0] * t.a.z() + w[1] * t.b.z() + w[2] * t.c.z();
    if (!top || z > *top) top = z;
  }
  return top;
}

std::optional<double> TriangleHeights::near(const Eigen::Vector2d& p) const {
  if (const auto z = at(p)) return z;
  const auto ci = int64_t(std::floor(p.x() / cell_)), cj = int64_t(std::floor(p.y() / cell_));
  double best = std::numeric_limits<double>::infinity();
  std::optional<double> z;
  for (int64_t i = ci - 1; i <= ci + 1; ++i)
    for (int64_t j = cj - 1; j <= cj + 1; ++j) {
      const auto it = cells_.find(key(i, j));
      if (it == cells_.end()) continue;
      for (const uint32_t k : it->second) {
        const Triangle& t = triangles_[k];
        Eigen::Vector3d w = Eigen::Vector3d::Zero();
        const double d = distance_to(p, t.a.head<2>(), t.b.head<2>(), t.c.head<2>(), w);
        if (d < best) best = d, z = w[0] * t.a.z() + w[1] * t.b.z() + w[2] * t.c.z();
      }
    }
  return z;
}

}  // namespace lidarloop
