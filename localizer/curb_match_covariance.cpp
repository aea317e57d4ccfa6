#include "localizer/curb_match_covariance.hpp"

#include <cmath>
#include <set>

#include <Eigen/Dense>

namespace lidarloop {
namespace {

// How many squares of side `cell` the points fall in.
size_t independent_count(const std::vector<Eigen::Vector2d>& points, double cell) {
  std::set<std::pair<long, long>> cells;
  for (const auto& p : points)
    cells.insert({std::lround(std::floor(p.x() / cell)), std::lround(std::floor(p.y() / cell))});
  return cells.size();
}

// The point-to-line residuals r = n^T (t + R f - m) of the features at `pose`, each against the map curb
// line nearest it (within the inlier distance): their Jacobian by (x, y, psi) is (n_x, n_y, n^T dR f).
struct PointToLine {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // sum of J J^T
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();     // sum of J r
  double squared_residuals = 0;
  std::vector<Eigen::Vector2d> inliers_vehicle;
};

PointToLine point_to_line(const std::vector<Eigen::Vector2d>& curbs_vehicle, const Pose2d& pose, const MapIndex& map,
                          const std::vector<Eigen::Vector2d>& map_tangents, double inlier_distance) {
  PointToLine sums;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  Eigen::Matrix2d R, dR;  // rotation and its derivative by psi
  R << c, -s, s, c;
  dR << -s, -c, c, -s;
  const Eigen::Vector2d t(pose.x, pose.y);
  for (const Eigen::Vector2d& f : curbs_vehicle) {
    const Eigen::Vector2d p = t + R * f;
    const size_t index = map.nearest_within(p, inlier_distance).first;
    if (index >= map_tangents.size()) continue;
    const Eigen::Vector2d n(-map_tangents[index].y(), map_tangents[index].x());
    const Eigen::Vector3d J(n.x(), n.y(), n.dot(dR * f));
    const double r = n.dot(p - map.points()[index]);
    sums.information.noalias() += J * J.transpose();
    sums.gradient += J * r;
    sums.squared_residuals += r * r;
    sums.inliers_vehicle.push_back(f);
  }
  return sums;
}

// A weak prior in every direction keeps the information invertible where the curbs say nothing.
Eigen::Matrix3d with_weak_prior(Eigen::Matrix3d information, const CurbMatchNoise& noise) {
  information.diagonal().array() += 1.0 / (noise.unconstrained_sigma_m * noise.unconstrained_sigma_m);
  return information;
}

// The covariance of the pose the sums were taken at: the residuals' variance (3 degrees of freedom taken
// by the pose), the information of the independent features only, and the floors.
Eigen::Matrix3d match_covariance(const PointToLine& sums, const CurbMatchNoise& noise) {
  const size_t inliers = sums.inliers_vehicle.size();
  constexpr int kPoseDof = 3;
  const double measured = inliers > kPoseDof ? sums.squared_residuals / double(inliers - kPoseDof) : 0.0;
  const double point_variance = std::max(measured, noise.min_point_sigma_m * noise.min_point_sigma_m);
  const double independent = double(independent_count(sums.inliers_vehicle, noise.correlation_length_m));
  Eigen::Matrix3d information = sums.information;
  if (inliers > 0) information *= independent / double(inliers);
  Eigen::Matrix3d covariance = with_weak_prior(information / point_variance, noise).inverse();
  covariance.diagonal() += Eigen::Vector3d(noise.min_sigma_m * noise.min_sigma_m, noise.min_sigma_m * noise.min_sigma_m,
                                           noise.min_sigma_yaw_rad * noise.min_sigma_yaw_rad);
  return covariance;
}

double along_sigma(const Eigen::Matrix3d& covariance, double yaw) {
  const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw));
  return std::sqrt(forward.dot(covariance.topLeftCorner<2, 2>() * forward));
}

}  // namespace

CurbMatchQuality finish_curb_match(const std::vector<Eigen::Vector2d>& curbs_vehicle, Pose2d pose, const MapIndex& map,
                                   const std::vector<Eigen::Vector2d>& map_tangents, const CurbMatchNoise& noise) {
  for (int k = 0;; ++k) {
    const PointToLine sums = point_to_line(curbs_vehicle, pose, map, map_tangents, noise.inlier_distance_m);
    // The covariance (a set over the features) only where it is used: to decide on the first step, and
    // for the pose the finish ends at.
    auto quality = [&] {
      CurbMatchQuality q;
      q.pose = pose;
      q.inliers = sums.inliers_vehicle.size();
      q.inlier_ratio = curbs_vehicle.empty() ? 0.0 : double(q.inliers) / double(curbs_vehicle.size());
      q.covariance = match_covariance(sums, noise);
      return q;
    };
    if (k == noise.refine_iterations || sums.inliers_vehicle.empty()) return quality();
    // Where the curbs leave the position along the road open (a straight), ICP has converged on what
    // they do fix, and a step would only follow their noise along it.
    if (k == 0) {
      const CurbMatchQuality q = quality();
      if (along_sigma(q.covariance, pose.yaw) > noise.inlier_distance_m) return q;
    }
    // Residuals in units of the detector's noise, so that the weak prior weighs as in the covariance.
    const double variance = noise.min_point_sigma_m * noise.min_point_sigma_m;
    const Eigen::Vector3d step =
        -with_weak_prior(sums.information / variance, noise).ldlt().solve(sums.gradient / variance);
    // Beyond the inlier distance the nearest lines are other lines: the linearisation no longer holds.
    if (!step.allFinite() || step.head<2>().norm() > noise.inlier_distance_m) return quality();
    pose = {pose.x + step.x(), pose.y + step.y(), wrap_angle(pose.yaw + step.z())};
  }
}

CurbMatchQuality curb_match_quality(const std::vector<Eigen::Vector2d>& curbs_vehicle, const Pose2d& pose,
                                    const MapIndex& map, const std::vector<Eigen::Vector2d>& map_tangents,
                                    CurbMatchNoise noise) {
  noise.refine_iterations = 0;
  return finish_curb_match(curbs_vehicle, pose, map, map_tangents, noise);
}

}  // namespace lidarloop
