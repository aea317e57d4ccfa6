#include "localizer/gps_jitter.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace lidarloop {
namespace {

// The medians of chi^2 with 2 and 1 degrees of freedom over their means (2 and 1): a median of the
// changes divided by these estimates the mean, as a jump among them does not move it.
constexpr double kMedianOverMeanChi2Dof2 = 0.6931;  // ln 2
constexpr double kMedianOverMeanChi2Dof1 = 0.4549;

double median(std::vector<double> v) {
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);  // of two, the larger: the cautious gate
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

bool GpsJitter::jump(const Eigen::Vector2d& change, double level_xy, double level_yaw) const {
  // |change|^2 / (2 variance) is chi^2 distributed: 2 xy / level with 2 dof, yaw / level with 1.
  return (level_xy > 0 && 2 * change.x() > p_.gate_xy * level_xy) ||
         (level_yaw > 0 && change.y() > p_.gate_yaw * level_yaw);
}

Eigen::Vector2d GpsJitter::median_level(const std::vector<Eigen::Vector2d>& changes) {
  std::vector<double> xys, yaws;
  for (const Eigen::Vector2d& c : changes) {
    xys.push_back(c.x());
    yaws.push_back(c.y());
  }
  return {median(xys) / kMedianOverMeanChi2Dof2, median(yaws) / kMedianOverMeanChi2Dof1};
}

void GpsJitter::add(const Eigen::Vector3d& change) {
  if (!change.allFinite()) return;
  // Half the squared change per axis: the white variance of one fix.
  const Eigen::Vector2d c(0.25 * change.head<2>().squaredNorm(), 0.5 * change.z() * change.z());
  if (calibrated()) {
    if (jump(c, xy_, yaw_)) return;
    const double w = 1.0 / double(std::min(++samples_, p_.window));
    xy_ += w * (c.x() - xy_);
    yaw_ += w * (c.y() - yaw_);
    return;
  }
  // Not yet calibrated: gated by the median of the changes taken so far, and once there are enough of
  // them, all screened again by the median of all (a jump among the very first ones had no median to
  // meet); the estimate is the mean of those kept.
  if (first_.size() >= 2) {
    const Eigen::Vector2d level = median_level(first_);
    if (jump(c, level.x(), level.y())) return;
  }
  first_.push_back(c);
  if (int(first_.size()) >= p_.min_samples) {
    const Eigen::Vector2d level = median_level(first_);
    std::vector<Eigen::Vector2d> kept;
    for (const Eigen::Vector2d& f : first_)
      if (!jump(f, level.x(), level.y())) kept.push_back(f);
    first_ = kept;
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& f : first_) mean += f;
  mean /= double(first_.size());
  xy_ = mean.x();
  yaw_ = mean.y();
  samples_ = int(first_.size());
  if (calibrated()) first_.clear();
}

}  // namespace lidarloop
