#include "localizer/gps_jitter.hpp"

#include <algorithm>
#include <vector>

namespace lidarloop {

namespace {

double median(std::vector<double> v) {
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

void GpsJitter::add(const Eigen::Vector3d& change) {
  if (!change.allFinite()) return;
  // Half the squared change per axis: the white variance of one fix.
  const double xy = 0.25 * change.head<2>().squaredNorm(), yaw = 0.5 * change.z() * change.z();
  // |change|^2 / (2 variance) is chi^2 distributed: 2 xy / level with 2 dof, yaw / level with 1.
  auto jump = [&](double level_xy, double level_yaw) {
    return (level_xy > 0 && 2 * xy > p_.gate_xy * level_xy) || (level_yaw > 0 && yaw > p_.gate_yaw * level_yaw);
  };
  if (calibrated()) {
    if (jump(xy_, yaw_)) return;
  } else {
    // The median of a few is what one jump cannot move (two changes: their mean, the best there is).
    if (first_.size() >= 2) {
      std::vector<double> xys, yaws;
      for (const Eigen::Vector2d& f : first_) {
        xys.push_back(f.x());
        yaws.push_back(f.y());
      }
      if (jump(median(xys), median(yaws))) return;
    }
    first_.emplace_back(xy, yaw);
  }
  const double w = 1.0 / double(std::min(++samples_, p_.window));
  xy_ += w * (xy - xy_);
  yaw_ += w * (yaw - yaw_);
}

}  // namespace lidarloop
