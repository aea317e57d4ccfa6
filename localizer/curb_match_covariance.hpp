#pragma once
// How well a curb match pins the pose down, for the Kalman filter's curb observation (paper 3.3).
// Point-to-point ICP (Eq. 9) finds the transform but says nothing about its uncertainty, and the
// uncertainty is very anisotropic: curbs along a straight road fix the lateral position and the heading
// but leave the longitudinal free, which is why the map also has an intensity layer (road paint fixes
// the position along the road). Each matched curb constrains the pose only across its map curb line, so
// the information of the match is the sum of point-to-line Jacobians, and its inverse is the
// observation covariance.
#include <vector>

#include <Eigen/Core>

#include "common/units.hpp"
#include "common/vehicle_messages.hpp"
#include "localizer/probabilistic_icp.hpp"

namespace lidarloop {

struct CurbMatchNoise {
  // The across-curb noise of one feature is measured, per match, from the residuals of its features to
  // the map's curb lines; this is its floor (m): the detector's centimetres.
  double min_point_sigma_m = 0.01;
  // The features are not independent: those along the same few metres of curb share the map's
  // digitising error and the odometry that placed their frames (Eq. 4-5 accumulates frames over a few
  // metres of driving). Features count as one per square of this side (m) that holds any.
  double correlation_length_m = 4.0;
  double inlier_distance_m = 1.0;  // features farther from the map than this carry no information (d_g)
  // Floors, so that a perfect-looking match is never trusted beyond what a map can be trusted. The
  // position's is set from the scenario suite's consistency, not from a source: at 0.03 m this floor
  // alone made the filter claim 2-3 times its lateral error (mean NEES 0.14 on dynamic_campus; 0.84 at
  // 0.01 m). The heading's is the survey's: the map's curbs are placed with the mapping car's heading,
  // 0.050 deg RMS (Applanix POS LV 220 datasheet, RTK; mapping/survey_error.hpp). At 0.115 deg, set like
  // the position's, the filter claimed 2.5 times its heading scatter (suite mean heading NEES 0.47;
  // 0.56 at 0.05 deg, misleading frames 0 and 1 of 3694).
  double min_sigma_m = 0.01;
  double min_sigma_yaw_rad = 0.05 * kDeg;
  // A direction without any curb information gets this standard deviation rather than an infinite one
  // (an observation with a huge variance leaves the filter's estimate there as it was).
  double unconstrained_sigma_m = 100.0;
  // Gauss-Newton steps on the point-to-line residuals after probabilistic ICP (finish_curb_match; the
  // proposed method only); 0: none.
  int refine_iterations = 3;
};

struct CurbMatchQuality {
  Pose2d pose;                                               // the matched pose this is the quality of
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // of (x, y, psi), local frame
  size_t inliers = 0;
  double inlier_ratio = 0;
};

// ICP's answer `pose` finished by Gauss-Newton on the same point-to-line residuals whose information the
// covariance is, and the quality at the pose it ends at (its `pose`). Point-to-point ICP crawls along a
// direction the curbs barely constrain (in a bend, the arc turned about its centre ties the position
// along the road to the heading), so its answer stays near the prior there, and the covariance of a
// converged match then counted the prior twice: at a bend's exit the curbs claimed 0.11 m along the
// road while 0.2-0.45 m off (closed_loop_campus at b9e57ab). Only where the curbs place the car along
// the road to within the inlier distance (a bend's entry and exit, a corner): elsewhere ICP has
// converged on what they fix, and steps followed their noise along a straight by a metre. A step that
// would move the car beyond the inlier distance ends it.
CurbMatchQuality finish_curb_match(const std::vector<Eigen::Vector2d>& curbs_vehicle, Pose2d pose, const MapIndex& map,
                                   const std::vector<Eigen::Vector2d>& map_tangents, const CurbMatchNoise& noise);

// The quality of the match at `pose` as it is (no steps). curbs_vehicle: the curb features in the vehicle
// frame. The map's points and unit tangents (CurbLayer::tangents) index as `map`'s points.
CurbMatchQuality curb_match_quality(const std::vector<Eigen::Vector2d>& curbs_vehicle, const Pose2d& pose,
                                    const MapIndex& map, const std::vector<Eigen::Vector2d>& map_tangents,
                                    CurbMatchNoise noise);

}  // namespace lidarloop
