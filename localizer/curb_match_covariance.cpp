#include "localizer/curb_match_covariance.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace lidarloop {

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
  for (const Eigen::Vector2d& f : curbs_vehicle) {
    const size_t index = map.nearest_within(t + R * f, noise.inlier_distance_m).first;
    if (index >= map_tangents.size()) continue;
    const Eigen::Vector2d n(-map_tangents[index].y(), map_tangents[index].x());
    const Eigen::Vector3d J(n.x(), n.y(), n.dot(dR * f));
    information.noalias() += J * J.transpose();
    ++q.inliers;
  }
  q.inlier_ratio = curbs_vehicle.empty() ? 0.0 : double(q.inliers) / double(curbs_vehicle.size());
  information /= noise.point_sigma_m * noise.point_sigma_m;
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
