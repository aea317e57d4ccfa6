#pragma once
// Obstacle rejection (paper section 2.1.2): the LiDAR points inside the driving corridor are mostly
// road. A plane fitted by least squares (Eq. 2) to the lowest xi % of them is the ground; points more
// than d_sigma above it (Eq. 3) are obstacles (cars, pedestrians) and are removed before curb detection
// and map matching, so they cannot be mistaken for curbs.
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

// Table I defaults.
struct ObstacleParams {
  // xi: share of the corridor points, lowest first, used for the ground fit. The top (1 - xi) are
  // assumed to hold the obstacles, so they cannot drag the plane upwards.
  double ground_fraction = 0.95;
  double obstacle_distance = 0.5;  // d_sigma (m)
  // Beyond the paper. Eq. 2 on the lowest xi % assumes obstacles make fewer than 1 - xi of the corridor
  // points. A coach alongside is a wall of returns, far more than 5 %: the "lowest 95 %" climb its side
  // and the plane tilts towards it (by 19 deg in bus_occlusion, so its flank counted as ground). The
  // ground is the lowest surface, so the fit sees one point per cell of this size, the lowest return
  // in it: a wall covers few cells however many returns it makes.
  double ground_cell_m = 1.0;
  // The plane is then fitted again to all points within this distance of the first one (m).
  double ground_refit_distance = 0.2;
};

// z = a0 x + a1 y + a2 (Eq. 2), in the vehicle frame (z up).
struct Plane {
  double a0 = 0, a1 = 0, a2 = 0;
};

// Sorts the points by z, keeps the lowest `fraction` (at least 3) and solves the normal equations of
// Eq. 2. Non-finite points are ignored. nullopt with fewer than 3 finite points, fraction not in
// (0, 1], or a degenerate system (the kept points are collinear in x-y, or a vertical plane).
std::optional<Plane> fit_ground_plane(std::vector<Eigen::Vector3d> points, double fraction);

// Eq. 3: perpendicular distance from p to the plane (always >= 0).
double distance_to_plane(const Plane& plane, const Eigen::Vector3d& p);
// Signed perpendicular distance: positive above the plane (z larger than the plane's z at (x, y)).
double height_above_plane(const Plane& plane, const Eigen::Vector3d& p);

// The points with z replaced by their height above the plane (x, y kept): the scan as a level sensor
// over flat ground would see it. A car on a crowned road rolls by the crown's slope, about 1 deg at 2 %,
// which lifts the road 9 cm at 5 m to one side and sinks it on the other.
std::vector<Eigen::Vector3d> level_to_plane(const std::vector<Eigen::Vector3d>& points, const Plane& plane);
// level_to_plane a point at a time, the normal's length taken once: for a loop that reads the scan
// anyway (curb detection) and need not copy it first.
class PlaneLeveller {
 public:
  explicit PlaneLeveller(const Plane& plane);
  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const { return {p.x(), p.y(), height(p)}; }
  // height_above_plane, without its square root a point.
  double height(const Eigen::Vector3d& p) const {
    return (p.z() - plane_.a0 * p.x() - plane_.a1 * p.y() - plane_.a2) / normal_;
  }

 private:
  Plane plane_;
  double normal_;  // the length of the plane's normal (a0, a1, -1)
};

struct ObstacleSplit {
  std::vector<Eigen::Vector3d> ground, obstacles;
  // Where each ground / obstacle point sits in the input, so callers can carry per-point data along.
  std::vector<size_t> ground_index, obstacle_index;
  Plane plane;
  bool plane_ok = false;
};

// corridor_points: vehicle frame (z up), already inside the driving corridor. Non-finite points are
// dropped first (in neither output). The plane: Eq. 2 on the lowest xi % of the cells' lowest points,
// refitted on all points near it (see ObstacleParams). Obstacle = more than d_sigma from the plane (Eq. 3) AND above
// it. Eq. 3 uses |d|, but a point far below the road cannot be something the car drives into or something that hides a
// curb: it is a reflection (wet road, glass; the mirrored return lands under the ground), a dip beyond the fitted
// patch, or a ditch. Calling it an obstacle would only remove ground evidence. Without a plane (fewer than 3 points,
// degenerate) nothing is rejected: every point is ground, which degrades to plain ICP rather than to throwing the scan
// away.
ObstacleSplit reject_obstacles(const std::vector<Eigen::Vector3d>& corridor_points, const ObstacleParams& params = {});

}  // namespace lidarloop
