#include "localizer/body_roll.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "common/units.hpp"

namespace lidarloop {

namespace {
constexpr double kGravity = 9.80665;  // m/s^2, standard gravity (ISO 80000-3)
constexpr double kMaxStepS = 0.005;   // semi-implicit Euler: w h < 0.05 at 1.5 Hz, as a CAN gap may be long
}  // namespace

void BodyRoll::step(double lateral_acceleration, double dt) {
  const double w = 2 * M_PI * p_.frequency_hz;
  const double target = p_.gradient_deg_per_g * kDeg * lateral_acceleration / kGravity;
  if (!std::isfinite(target) || !std::isfinite(dt)) return;
  for (double done = 0; done < dt;) {
    const double h = std::min(kMaxStepS, dt - done);
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
