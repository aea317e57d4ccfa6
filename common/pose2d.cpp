#include "common/pose2d.hpp"

#include <cmath>
#include <numbers>

namespace lidarloop {

double wrap_angle(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);  // [-pi, pi]
  return a <= -std::numbers::pi ? a + 2 * std::numbers::pi : a;
}

Eigen::Vector2d Pose2d::apply(const Eigen::Vector2d& p) const { return PoseApplier(*this)(p); }

PoseApplier::PoseApplier(const Pose2d& pose) : c(std::cos(pose.yaw)), s(std::sin(pose.yaw)), x(pose.x), y(pose.y) {}

Pose2d Pose2d::compose(const Pose2d& b) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {x + c * b.x - s * b.y, y + s * b.x + c * b.y, wrap_angle(yaw + b.yaw)};
}

Pose2d Pose2d::inverse() const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  // R^T (p - t): the translation is -R^T t.
  return {-(c * x + s * y), -(-s * x + c * y), wrap_angle(-yaw)};
}

Pose2d relative(const Pose2d& a, const Pose2d& b) {
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, wrap_angle(b.yaw - a.yaw)};
}

}  // namespace lidarloop
