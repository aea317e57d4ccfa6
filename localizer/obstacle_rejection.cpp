#include "localizer/obstacle_rejection.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace lidarloop {

namespace {

bool finite(const Eigen::Vector3d& p) { return p.allFinite(); }

// The length of the plane's normal (a0, a1, -1): height_above_plane divides by it.
double normal_length(const Plane& plane) { return std::sqrt(plane.a0 * plane.a0 + plane.a1 * plane.a1 + 1.0); }

// height_above_plane with the normal's length given: loops over a scan's points take the square root
// once, not once a point.
double height_above(const Plane& plane, double normal, const Eigen::Vector3d& p) {
  return (p.z() - plane.a0 * p.x() - plane.a1 * p.y() - plane.a2) / normal;
}

// Beyond this many cells the cells grow instead: a caller may pass points spread over kilometres.
constexpr double kMaxGroundCells = 1 << 20;

// The lowest of `points` (all finite) in each square cell of side `cell_m`, in cell order.
std::vector<Eigen::Vector3d> lowest_per_cell(const std::vector<Eigen::Vector3d>& points, double cell_m) {
  if (points.empty()) return {};
  Eigen::Vector2d lo = points[0].head<2>(), hi = lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const Eigen::Vector2d extent = hi - lo;
  const double cell = std::max(cell_m, std::sqrt((extent.x() + cell_m) * (extent.y() + cell_m) / kMaxGroundCells));
  const size_t cols = size_t(extent.x() / cell) + 1, rows = size_t(extent.y() / cell) + 1;
  std::vector<long> lowest(cols * rows, -1);
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t c = std::min(size_t((points[i].x() - lo.x()) / cell), cols - 1);
    const size_t r = std::min(size_t((points[i].y() - lo.y()) / cell), rows - 1);
    long& k = lowest[r * cols + c];
    if (k < 0 || points[i].z() < points[size_t(k)].z()) k = long(i);
  }
  std::vector<Eigen::Vector3d> out;
  for (long k : lowest)
    if (k >= 0) out.push_back(points[size_t(k)]);
  return out;
}

// The ground plane of reject_obstacles: Eq. 2 on the cells' lowest points, then again on every point
// near that plane. The second fit matters: the lowest of a cell's noisy returns lies below the road by
// about twice the range noise, so the first plane sits a few centimetres low. Too few cells for a plane
// (a handful of points): Eq. 2 on the points themselves.
std::optional<Plane> fit_ground(const std::vector<Eigen::Vector3d>& points, const ObstacleParams& params) {
  const std::optional<Plane> first =
      fit_ground_plane(lowest_per_cell(points, params.ground_cell_m), params.ground_fraction);
  if (!first) return fit_ground_plane(points, params.ground_fraction);
  std::vector<Eigen::Vector3d> near;
  near.reserve(points.size());
  const double normal = normal_length(*first);
  for (const auto& p : points)  // Eq. 3's distance_to_plane
    if (std::abs(height_above(*first, normal, p)) <= params.ground_refit_distance) near.push_back(p);
  const std::optional<Plane> refit = fit_ground_plane(std::move(near), 1.0);
  return refit ? refit : first;
}

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
  return height_above(plane, normal_length(plane), p);
}

PlaneLeveller::PlaneLeveller(const Plane& plane) : plane_(plane), normal_(normal_length(plane)) {}

std::vector<Eigen::Vector3d> level_to_plane(const std::vector<Eigen::Vector3d>& points, const Plane& plane) {
  std::vector<Eigen::Vector3d> out(points.size());
  const PlaneLeveller level(plane);
  std::transform(points.begin(), points.end(), out.begin(), level);
  return out;
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

  const auto plane = fit_ground(pts, params);
  if (!plane) {
    out.ground = std::move(pts);
    out.ground_index = std::move(index);
    return out;
  }
  out.plane = *plane;
  out.plane_ok = true;
  out.ground.reserve(pts.size());
  out.ground_index.reserve(pts.size());
  const double normal = normal_length(*plane);
  for (size_t k = 0; k < pts.size(); ++k) {
    // Eq. 3 with the sign kept: d_i > d_sigma and above the plane (see the header for why).
    if (height_above(*plane, normal, pts[k]) > params.obstacle_distance) {
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
