#pragma once
// Evaluating an OpenDRIVE road (sim/opendrive_file.hpp): its reference line's pose at s, where each
// lane's edges lie across it (t) and how high its surface is. Formulas are the ASAM OpenDRIVE 1.8
// specification's (sections 9 reference line, 10.3-10.5 elevation and superelevation, 11 lanes).
#include <Eigen/Core>

#include "sim/opendrive_file.hpp"

namespace lidarloop {

struct OdrPose {
  double x = 0, y = 0, hdg = 0;
};

// The clothoid's integrals: (integral of cos, integral of sin) over [0, u] of the heading
// k0 tau + dk tau^2 / 2, a clothoid whose curvature starts at k0 and changes by dk per metre. Composite
// 5-point Gauss-Legendre quadrature on panels over which the heading turns at most 0.25 rad: exact for
// the heading's Taylor terms to the 9th power, so the relative error per panel is below 1e-12 and the
// end point of a 1 km spiral is within a micrometre of the Fresnel integrals (tests/sim/test_opendrive_file.cpp).
Eigen::Vector2d clothoid_integral(double k0, double dk, double u);

// The pose a distance ds (0 <= ds <= g.length) along one planView geometry. poly3 is followed by its
// arc length (found by quadrature and Newton's method); paramPoly3 by its parameter, p = ds (arcLength)
// or ds / length (normalized), as the specification defines it.
OdrPose geometry_pose(const OdrGeometry& g, double ds);
// The reference line at s (clamped to the road).
OdrPose reference_pose(const OdrRoad& road, double s);

// A lane's edges across the road at s: t of its inner and outer edge (left positive), the lane offset
// included. The centre lane has both at the offset reference line.
struct OdrLaneEdges {
  double inner = 0, outer = 0;
};
OdrLaneEdges lane_edges(const OdrRoad& road, size_t section, int lane_id, double s);
// The lane's width (outer minus inner edge, unsigned) at s.
double lane_width(const OdrRoad& road, size_t section, int lane_id, double s);
// The lane's height above the road surface at s, a fraction `across` (0 inner edge, 1 outer) of its width.
double lane_height(const OdrLane& lane, double s_in_section, double across);

// A point of the road at (s, t), `dz` above the road's surface there: elevation, then the
// superelevation's roll about the reference line (z changes by t tan(roll): a positive roll lowers the
// right side, t < 0).
Eigen::Vector3d road_point(const OdrRoad& road, double s, double t, double dz = 0);
// The surface of a lane at (s, t): the road's surface (unrolled for a `level` lane, which keeps the
// height of its inner edge) and the lane's own height.
Eigen::Vector3d lane_surface_point(const OdrRoad& road, size_t section, const OdrLane& lane, double s, double t);

}  // namespace lidarloop
