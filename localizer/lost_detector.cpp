#include "localizer/lost_detector.hpp"

#include <cmath>

#include "common/units.hpp"

namespace lidarloop {

void LostDetector::start_search() {
  lost_ = true;
  found_ = false;
  agreements_along_ = agreements_across_ = 0;
}

void LostDetector::disagree(const Disagreement& d) {
  disagreements(d.stamp_ns);
  recent_.push_back(d);
  agreements_along_ = agreements_across_ = 0;
  if (int(recent_.size()) >= p_.min_disagreements) start_search();
}

void LostDetector::agree(bool along, bool across, double position_sigma_m, const Eigen::Vector2d& innovation) {
  if (!lost_) return;
  agreements_along_ += along && std::abs(innovation.x()) <= p_.converged_sigma_m;
  agreements_across_ += across && std::abs(innovation.y()) <= p_.converged_sigma_m;
  // Confirmed: a found pose that enough matches agree with, or a cold start the narrow matchers
  // converged on their own.
  const bool agreed = agreements_along_ >= p_.confirmations && agreements_across_ >= p_.confirmations;
  if (agreed && (found_ || position_sigma_m <= p_.converged_sigma_m)) {
    lost_ = found_ = false;
    agreements_along_ = agreements_across_ = 0;
  }
}

void LostDetector::found() {
  found_ = true;
  agreements_along_ = agreements_across_ = 0;
  recent_.clear();
}

bool LostDetector::only_gps_disagrees(int64_t t_ns) {
  for (const Disagreement& d : disagreements(t_ns))
    if (!d.gps) return false;
  return true;
}

const std::deque<Disagreement>& LostDetector::disagreements(int64_t t_ns) {
  const int64_t window_ns = int64_t(p_.window_s * kNsPerS);
  while (!recent_.empty() && recent_.front().stamp_ns < t_ns - window_ns) recent_.pop_front();
  return recent_;
}

}  // namespace lidarloop
