#pragma once
// 2-D polyline geometry for road centrelines and markings.
#include <optional>

#include <Eigen/Geometry>

#include "common/curb_map_file.hpp"  // Polyline2d

namespace lidarloop {

double polyline_length(const Polyline2d& line);

struct PolylineSample {
  Eigen::Vector2d point;
  Eigen::Vector2d tangent;  // unit
};
// Point and direction at arc length s (clamped to the line).
PolylineSample sample_polyline(const Polyline2d& line, double s);

// Arc length of the point of the line nearest to p.
double project_onto_polyline(const Polyline2d& line, const Eigen::Vector2d& p);

// Rounds every interior corner (and the closing corner of a closed line) with a circular arc of
// `radius`, shrunk where the adjacent segments are too short; arcs are split every `max_step_rad`.
// A closed line is given without its repeated first point and returned with it.
Polyline2d fillet_polyline(const Polyline2d& line, double radius, bool closed, double max_step_rad);

// The line as a driver steers it: resampled every `step` metres and each sample moved to the Gaussian-
// weighted mean (standard deviation `sigma` metres of arc length) of the line around it, the window
// shrunk symmetrically near the ends so that the ends stay put and a straight line stays straight. A
// kink of angle a becomes a bend of curvature about a / (2.5 sigma); an arc of radius R moves inwards by
// about sigma^2 / (2 R).
Polyline2d smooth_polyline(const Polyline2d& line, double sigma, double step);

// The line shifted sideways by `offset` (positive = left of the direction of travel), mitred joins.
Polyline2d offset_polyline(const Polyline2d& line, double offset, bool closed);

bool segments_intersect(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
                        const Eigen::Vector2d& b1);
// Indices (i, j) of the first two non-adjacent segments that cross, if any.
std::optional<std::pair<size_t, size_t>> find_self_intersection(const Polyline2d& line, bool closed);

}  // namespace lidarloop
