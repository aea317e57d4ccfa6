#include "localizer/gps_jitter.hpp"

#include <algorithm>

namespace lidarloop {

void GpsJitter::add(const Eigen::Vector3d& change) {
  if (!change.allFinite()) return;
  // Half the squared change per axis: the white variance of one fix.
  const double xy = 0.25 * change.head<2>().squaredNorm(), yaw = 0.5 * change.z() * change.z();
  // |change|^2 / (2 variance) is chi^2 distributed: 2 xy / xy_ with 2 dof, yaw / yaw_ with 1.
  const bool jump = (xy_ > 0 && 2 * xy > p_.gate_xy * xy_) || (yaw_ > 0 && yaw > p_.gate_yaw * yaw_);
  if (calibrated() && jump) return;
  const double w = 1.0 / double(std::min(++samples_, p_.window));
  xy_ += w * (xy - xy_);
  yaw_ += w * (yaw - yaw_);
}

}  // namespace lidarloop
