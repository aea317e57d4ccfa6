#include "localizer/protection_bound.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lidarloop {

double normal_two_sided_quantile(double probability) {
  if (!(probability > 0 && probability < 1)) throw std::invalid_argument("integrity probability must lie in (0, 1)");
  // P(|N| > k) = erfc(k / sqrt 2), decreasing in k: bisection to well below any use's precision.
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > 1 - probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

ProtectionBounds protection_bounds(const Eigen::Matrix3d& covariance, const Pose2d& pose,
                                   const std::deque<Disagreement>& refused, const IntegrityParams& params) {
  const double k = normal_two_sided_quantile(params.probability);
  const Eigen::Vector2d forward(std::cos(pose.yaw), std::sin(pose.yaw)), left(-forward.y(), forward.x());
  const Eigen::Matrix2d P = covariance.topLeftCorner<2, 2>();
  auto bound = [&](const Eigen::Vector2d& u) {
    double widest = 0;
    for (const Disagreement& d : refused) widest = std::max(widest, std::abs(u.dot(d.innovation)));
    return k * std::sqrt(std::max(0.0, u.dot(P * u))) + widest;
  };
  return {bound(left), bound(forward)};
}

}  // namespace lidarloop
