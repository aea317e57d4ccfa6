#include "localizer/obstacle_rejection.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace lidarloop {

namespace {

bool finite(const Eigen::Vector3d& p) { return p.allFinite(); }

}  // namespace

std::optional<Plane> fit_ground_plane(std::vector<Eigen::Vector3d> points, double fraction) {
  if (!(fraction > 0 && fraction <= 1)) return std::nullopt;
  points.erase(std::remove_if(points.begin(), points.end(), [](const Eigen::Vector3d& p) { return !finite(p); }),
               points.end());
  if (points.size() < 3) return std::nullopt;

  // The lowest xi % by elevation. Only which points are kept matters, not their order, so a partial
  // selection (nth_element, O(n)) gives the same set as the paper's full sort.
  const auto n_keep = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(points.size()))), 3, points.size());
  if (n_keep < points.size()) {
    std::nth_element(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(n_keep - 1), points.end(),
                     [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
  }

  // Eq. 2 in coordinates centred on the kept points' mean x-y: the same solution, but the x^2 sums of
  // points 40 m out no longer dwarf the n_d entry, which keeps the 3x3 system well conditioned.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < n_keep; ++i) mean += points[i].head<2>();
  mean /= static_cast<double>(n_keep);

  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n_keep; ++i) {
    const Eigen::Vector3d row(points[i].x() - mean.x(), points[i].y() - mean.y(), 1.0);
    A.noalias() += row * row.transpose();  // [sum x^2, sum xy, sum x; ...; sum x, sum y, n_d]
    b.noalias() += row * points[i].z();    // [sum xz, sum yz, sum z]
  }

  // Degenerate: the x-y scatter has (nearly) no extent in some direction, e.g. all points on a line
  // (a single scan ring segment). The plane would then tilt freely about that line.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> scatter(A.topLeftCorner<2, 2>());
  const double max_ev = scatter.eigenvalues().maxCoeff(), min_ev = scatter.eigenvalues().minCoeff();
  if (!(max_ev > 0) || min_ev <= 1e-9 * max_ev) return std::nullopt;

  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  const Eigen::Vector3d a = ldlt.solve(b);
  if (!a.allFinite()) return std::nullopt;
  // Undo the centring: z = a0 (x - mx) + a1 (y - my) + c  =>  a2 = c - a0 mx - a1 my.
  return Plane{a(0), a(1), a(2) - a(0) * mean.x() - a(1) * mean.y()};
}

double height_above_plane(const Plane& plane, const Eigen::Vector3d& p) {
  return (p.z() - plane.a0 * p.x() - plane.a1 * p.y() - plane.a2) /
         std::sqrt(plane.a0 * plane.a0 + plane.a1 * plane.a1 + 1.0);
}

double distance_to_plane(const Plane& plane, const Eigen::Vector3d& p) {
  return std::abs(height_above_plane(plane, p));  // Eq. 3
}

ObstacleSplit reject_obstacles(const std::vector<Eigen::Vector3d>& corridor_points, const ObstacleParams& params) {
  ObstacleSplit out;
  std::vector<Eigen::Vector3d> pts;
  std::vector<size_t> index;
  pts.reserve(corridor_points.size());
  index.reserve(corridor_points.size());
  for (size_t i = 0; i < corridor_points.size(); ++i)
    if (finite(corridor_points[i])) {
      pts.push_back(corridor_points[i]);
      index.push_back(i);
    }

  const auto plane = fit_ground_plane(pts, params.ground_fraction);
  if (!plane) {
    out.ground = std::move(pts);
    out.ground_index = std::move(index);
    return out;
  }
  out.plane = *plane;
  out.plane_ok = true;
  out.ground.reserve(pts.size());
  out.ground_index.reserve(pts.size());
  for (size_t k = 0; k < pts.size(); ++k) {
    // Eq. 3 with the sign kept: d_i > d_sigma and above the plane (see the header for why).
    if (height_above_plane(*plane, pts[k]) > params.obstacle_distance) {
      out.obstacles.push_back(pts[k]);
      out.obstacle_index.push_back(index[k]);
    } else {
      out.ground.push_back(pts[k]);
      out.ground_index.push_back(index[k]);
    }
  }
  return out;
}

}  // namespace lidarloop
