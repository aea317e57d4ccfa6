#include "common/map_observation.hpp"

#include <Eigen/Geometry>

namespace lidarloop {

Eigen::Matrix3d in_car_axes(const Eigen::Matrix3d& covariance, double yaw) {
  // Block by block, so that an infinite heading variance stays where it is (inf times 0 is NaN).
  const Eigen::Matrix2d to_car = Eigen::Rotation2Dd(-yaw).toRotationMatrix();
  Eigen::Matrix3d out;
  out.topLeftCorner<2, 2>() = to_car * covariance.topLeftCorner<2, 2>() * to_car.transpose();
  out.topRightCorner<2, 1>() = to_car * covariance.topRightCorner<2, 1>();
  out.bottomLeftCorner<1, 2>() = out.topRightCorner<2, 1>().transpose();
  out(2, 2) = covariance(2, 2);
  return out;
}

}  // namespace lidarloop
