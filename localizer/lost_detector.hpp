#pragma once
// When the localizer is lost, and how it is found again. "Lost" means its pose is not to be trusted:
// after a cold start until a map match has pinned it down, or when the observations stop agreeing with
// the filter (the map's matches refused by the innovation gate, a GPS fix beyond the receiver's own
// error or stepping away from its usual level: gps_step_detector.hpp), several times within a short
// window.
// While lost the localizer searches wide (relocalization); a pose found is then confirmed by a few map
// matches that agree with it before `lost` clears.
//
// The disagreements also widen the protection bounds (protection_bound.hpp): an observation the filter
// refused says where else the car may be.
#include <cstdint>
#include <deque>

#include <Eigen/Core>

namespace lidarloop {

struct LostParams {
  // Disagreements are counted over this window (s), and this many make the localizer lost. The GPS at
  // 10 Hz alone raises it 0.4 s after a jump; the map's matches (10 Hz) alone after 4 of 5 scans.
  double window_s = 0.5;
  int min_disagreements = 4;
  // Map matches in a row agreeing with a relocalized pose, on each axis of the car, before it is trusted
  // again (curbs along a straight road confirm only across it).
  int confirmations = 3;
  // Cold start: the filter counts as converged once its position sigma (largest axis, m) is this small
  // and a map match agreed with it (the map matchers' grown windows found it without a wide search).
  // A match agrees, on an axis it pinned down, only if the filter's pose was within this of it there: one
  // that pulls the filter metres (a filter still converging) confirms nothing yet.
  double converged_sigma_m = 0.3;
};

// A disagreement: when, and the offset the refused observation pointed to (local frame, m).
struct Disagreement {
  int64_t stamp_ns = 0;
  Eigen::Vector2d innovation{0, 0};
  bool gps = false;  // a GPS fix (else one of the map's matches)
};

class LostDetector {
 public:
  explicit LostDetector(const LostParams& params = {}) : p_(params) {}

  // A cold start (or a forced relocalization): lost, and a wide search wanted.
  void start_search();
  void disagree(const Disagreement& d);
  // A map match the filter accepted, the axes (of the car) it pinned down, and its innovation on them
  // (along, across: the match's position less the filter's before the update, m).
  void agree(bool along, bool across, double position_sigma_m, const Eigen::Vector2d& innovation);
  // A wide search found a pose and the filter was put there: now to be confirmed.
  void found();

  bool lost() const { return lost_; }
  bool searching() const { return lost_ && !found_; }
  // The disagreements within the window before t_ns.
  const std::deque<Disagreement>& disagreements(int64_t t_ns);
  // Whether all of those are the GPS's: the map still agrees with the filter.
  bool only_gps_disagrees(int64_t t_ns);

 private:
  LostParams p_;
  std::deque<Disagreement> recent_;
  bool lost_ = false, found_ = false;
  int agreements_along_ = 0, agreements_across_ = 0;
};

}  // namespace lidarloop
