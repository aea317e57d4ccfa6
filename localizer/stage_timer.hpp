#pragma once
// Wall time of a scope, added to a field in milliseconds when the scope ends. The localizer's stages
// time themselves with one line each, and every way out of a stage (early returns included) counts.
#include <chrono>

namespace lidarloop {

class StageTimer {
 public:
  // `total_ms` must outlive the timer; the time is added, so a stage run in several pieces sums up.
  explicit StageTimer(double& total_ms) : total_ms_(total_ms) {}
  ~StageTimer() { total_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - start_).count(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  double& total_ms_;
  Clock::time_point start_ = Clock::now();
};

}  // namespace lidarloop
