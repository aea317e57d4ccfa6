#include "scoring/observation_consistency.hpp"

#include <cmath>

#include "scoring/scorer.hpp"

namespace lidarloop {

ObservationConsistency observation_consistency(const std::vector<PoseStamped>& truth,
                                               const std::vector<MapObservation>& observations, double mount_yaw_rad,
                                               double informative_sigma_m) {
  ObservationConsistency out;
  Eigen::Vector3d nees_sum = Eigen::Vector3d::Zero(), error_sum = Eigen::Vector3d::Zero();
  for (const MapObservation& z : observations) {
    if (truth.empty() || z.stamp_ns < truth.front().stamp_ns || z.stamp_ns > truth.back().stamp_ns) continue;
    const Pose2d t = truth_at(truth, z.stamp_ns);
    const double true_yaw = wrap_angle(t.yaw + mount_yaw_rad);
    // What the observation would say if it were exact.
    const Eigen::Vector2d exact = Eigen::Vector2d(t.x, t.y) + z.yaw_coupling * wrap_angle(z.pose.yaw - true_yaw);
    const Eigen::Vector2d off = Eigen::Vector2d(z.pose.x, z.pose.y) - exact;
    const double c = std::cos(z.pose.yaw), s = std::sin(z.pose.yaw);
    // An intensity observation's heading is the prior's, not a measurement: its variance is infinite, so
    // the axis is skipped below.
    const Eigen::Vector3d error(c * off.x() + s * off.y(), -s * off.x() + c * off.y(),
                                wrap_angle(z.pose.yaw - true_yaw));
    for (int axis = 0; axis < 3; ++axis) {
      const double variance = z.covariance(axis, axis);
      if (!std::isfinite(variance) || !(variance > 0)) continue;
      if (axis < 2 && variance > informative_sigma_m * informative_sigma_m) continue;
      ++out.counts(axis);
      nees_sum(axis) += error(axis) * error(axis) / variance;
      error_sum(axis) += error(axis) * error(axis);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (out.counts(axis) == 0) continue;
    out.mean_nees(axis) = nees_sum(axis) / double(out.counts(axis));
    out.rms_error(axis) = std::sqrt(error_sum(axis) / double(out.counts(axis)));
  }
  return out;
}

}  // namespace lidarloop
