#pragma once
// The low-cost receiver's white noise, learnt from its own fixes. Two consecutive fixes differ by the
// car's motion, which odometry knows to millimetres over a tenth of a second, by the white noise of
// each, and by the bias's change over one period, negligible against it (the bias wanders over
// minutes). So the fix-to-fix change less odometry's motion has twice the white variance. The rest of
// the error the receiver reports (its stationary variance) is the slowly wandering bias, which the
// filter carries as a state (pose_filter.hpp).
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

struct GpsJitterParams {
  int window = 100;         // changes the running mean spans (a plain mean before, an exponential one after)
  int min_samples = 10;     // changes seen before the estimate is used: chi^2 with 20 dof, +-30 % at 1 sigma
  double gate_xy = 18.42;   // a change this improbable is a jump, not jitter: chi^2, 2 dof, 99.99 %
  double gate_yaw = 15.13;  // the same, 1 dof
};

class GpsJitter {
 public:
  explicit GpsJitter(const GpsJitterParams& params = {}) : p_(params) {}

  // One fix-to-fix change less odometry's motion (x, y in m, heading in rad). A jump is refused: beyond
  // the gates against the running mean once calibrated, and before that against the median of the
  // changes taken so far, all of which are screened again when there are enough (a jump among the
  // first few would otherwise be most of the estimate). So the caller need not know whether the GPS
  // jumped, which it could only judge against the filter's pose (and a filter moved by its matches,
  // lost or at a cold start, makes every fix look like a step).
  void add(const Eigen::Vector3d& change);
  bool calibrated() const { return samples_ >= p_.min_samples; }
  // The white variance per fix (x, y pooled: the receiver's horizontal noise is the same both ways;
  // heading). Zero before the first change.
  Eigen::Vector3d white_variance() const { return Eigen::Vector3d(xy_, xy_, yaw_); }

 private:
  GpsJitterParams p_;
  // A change (xy, yaw: half its squared size per axis) improbable against these levels of them.
  bool jump(const Eigen::Vector2d& change, double level_xy, double level_yaw) const;
  // The mean level of such changes, from their median.
  static Eigen::Vector2d median_level(const std::vector<Eigen::Vector2d>& changes);
  double xy_ = 0, yaw_ = 0;
  int samples_ = 0;
  std::vector<Eigen::Vector2d> first_;  // (xy, yaw) of each change taken before calibrated()
};

}  // namespace lidarloop
