#include "localizer/curb_match_covariance.hpp"
#include <set>

#include <cmath>

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

}  // namespace

CurbMatchQuality curb_match_quality(const std::vector<Eigen::Vector2d>& curbs_vehicle, const Pose2d& pose,
                                    const MapIndex& map, const std::vector<Eigen::Vector2d>& map_tangents,
                                    const CurbMatchNoise& noise) {
  CurbMatchQuality q;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  Eigen::Matrix2d R, dR;  // rotation and its derivative by psi
  R << c, -s, s, c;
  dR << -s, -c, c, -s;
  const Eigen::Vector2d t(pose.x, pose.y);

  // Point-to-line residual r = n^T (t + R f - m); its Jacobian by (x, y, psi) is (n_x, n_y, n^T dR f).
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double squared_residuals = 0;
  std::vector<Eigen::Vector2d> inliers_vehicle;
  for (const Eigen::Vector2d& f : curbs_vehicle) {
    const Eigen::Vector2d p = t + R * f;
    const size_t index = map.nearest_within(p, noise.inlier_distance_m).first;
    if (index >= map_tangents.size()) continue;
    const Eigen::Vector2d n(-map_tangents[index].y(), map_tangents[index].x());
    const Eigen::Vector3d J(n.x(), n.y(), n.dot(dR * f));
    information.noalias() += J * J.transpose();
    inliers_vehicle.push_back(f);
    squared_residuals += std::pow(n.dot(p - map.points()[index]), 2);
    ++q.inliers;
  }
  q.inlier_ratio = curbs_vehicle.empty() ? 0.0 : double(q.inliers) / double(curbs_vehicle.size());
  // The residuals' variance (3 degrees of freedom taken by the pose), and the information of the
  // independent features only.
  constexpr int kPoseDof = 3;
  const double measured = q.inliers > kPoseDof ? squared_residuals / double(q.inliers - kPoseDof) : 0.0;
  const double point_variance = std::max(measured, noise.min_point_sigma_m * noise.min_point_sigma_m);
  const double independent = double(independent_count(inliers_vehicle, noise.correlation_length_m));
  if (q.inliers > 0) information *= independent / double(q.inliers);
  information /= point_variance;
  // A weak prior in every direction keeps the inverse finite where the curbs say nothing.
  const double weak = 1.0 / (noise.unconstrained_sigma_m * noise.unconstrained_sigma_m);
  information.diagonal().array() += weak;
  q.covariance = information.inverse();
  q.covariance.diagonal() +=
      Eigen::Vector3d(noise.min_sigma_m * noise.min_sigma_m, noise.min_sigma_m * noise.min_sigma_m,
                      noise.min_sigma_yaw_rad * noise.min_sigma_yaw_rad);
  return q;
}

}  // namespace lidarloop
