#pragma once
// The one planar pose type: where a vehicle is in the local frame, or a rigid motion between two
// frames. x east, y north (m), yaw counter-clockwise from +x (rad), always in (-pi, pi].
#include <cstdint>

#include <Eigen/Core>

namespace lidarloop {

// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

struct Pose2d {
  double x = 0, y = 0, yaw = 0;

  // The point p of this pose's frame in the parent frame: R(yaw) p + (x, y).
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const;
  // this * b: b first, then this. (a.compose(b)).apply(p) == a.apply(b.apply(p)).
  Pose2d compose(const Pose2d& b) const;
  Pose2d inverse() const;
};

// One pose applied to many points (a scan's, ICP's curbs each iteration): Pose2d::apply with the sine and
// cosine computed once rather than per point; the same arithmetic, so the same results to the bit.
struct PoseApplier {
  explicit PoseApplier(const Pose2d& pose);
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
    return {c * p.x() - s * p.y() + x, s * p.x() + c * p.y() + y};
  }
  double c, s, x, y;
};

// a.inverse().compose(b), computed directly: b's pose in a's frame, i.e. the motion from a to b.
Pose2d relative(const Pose2d& a, const Pose2d& b);

struct PoseStamped {
  int64_t stamp_ns = 0;
  Pose2d pose;
};

}  // namespace lidarloop
