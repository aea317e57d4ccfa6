#pragma once
// Paths that the ego and traffic follow: lane centres along the world's roads, lines across
// crosswalks, or explicit waypoints; and positions on them by arc length.
#include <string>

#include <Eigen/Geometry>
#include <vector>

#include "common/vehicle_messages.hpp"
#include "sim/polyline.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct Path {
  Polyline2d points;  // closed paths repeat their first point
  bool closed = false;
  double length = 0;
  std::vector<double> arc;  // arc length at each point

  Pose2d pose_at(double s) const;       // position and heading at arc length s (wrapped if closed)
  double curvature_at(double s) const;  // signed (left positive), averaged over a few metres
  // Arc length of the point nearest to p among the segments within [from, to] (wrapped if closed).
  double project(const Eigen::Vector2d& p, double from, double to) const;
  double project(const Eigen::Vector2d& p) const { return project(p, 0, length); }
  double wrap(double s) const;
};

Path make_path(Polyline2d points, bool closed);

// A planar pose as a 3-D transform on the ground (z = 0).
Eigen::Isometry3d to_isometry(const Pose2d& pose);

enum class Lane { right, left };  // in the direction of travel

// The centre of a lane of `road`, driven forward (along the centreline) or backward. On a two-way road
// `right` is the outermost lane of the travel direction's half and `left` the innermost; on a one-way
// road they are its outermost lanes. `offset`, if set, overrides the lane with a lateral offset (m,
// positive = left of the centreline's direction).
Path lane_path(const RoadSpec& road, Lane lane, bool backward, const double* offset = nullptr);
// The lateral offset of that lane's centre from the centreline (m, positive = left of the centreline's
// direction), as lane_path takes it without `offset`.
double lane_offset(const RoadSpec& road, Lane lane, bool backward);

// A pedestrian's line across a road at a crosswalk, from the right sidewalk to the left one.
Path crosswalk_path(const RoadSpec& road, const CrosswalkSpec& crosswalk, bool from_left);

}  // namespace lidarloop
