#include "localizer/body_roll.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/units.hpp"

namespace lidarloop {

namespace {
// Semi-implicit Euler steps of at most this and a twentieth of the mode's period: w h <= 0.31, stable
// and within a percent of the exact response for every frequency and damping the parameters allow.
constexpr double kMaxStepS = 0.005;
constexpr double kStepsPerPeriod = 20;
constexpr double kSettlingTimes = 10;  // e^-10 of a transient left: at rest
}  // namespace

void BodyRoll::step(double lateral_acceleration, double dt) {
  const double w = 2 * std::numbers::pi * p_.frequency_hz;
  const double target = p_.gradient_deg_per_g * kDeg * lateral_acceleration / kGravity;
  if (!std::isfinite(target) || !std::isfinite(dt) || dt <= 0) return;
  if (dt > kSettlingTimes / (p_.damping_ratio * w)) {
    roll_ = target;
    rate_ = 0;
    return;
  }
  const double max_step = std::min(kMaxStepS, 1.0 / (kStepsPerPeriod * p_.frequency_hz));
  for (double done = 0; done < dt;) {
    const double h = std::min(max_step, dt - done);
    rate_ += h * (-w * w * (roll_ - target) - 2 * p_.damping_ratio * w * rate_);
    roll_ += h * rate_;
    done += h;
  }
}

void unroll(std::vector<Eigen::Vector3d>& points, double roll, double pivot_height) {
  if (roll == 0) return;
  const double c = std::cos(roll), s = std::sin(roll);
  for (Eigen::Vector3d& p : points) {
    const double y = p.y(), z = p.z() - pivot_height;
    p.y() = c * y - s * z;
    p.z() = s * y + c * z + pivot_height;
  }
}

}  // namespace lidarloop
