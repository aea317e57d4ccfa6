#pragma once
// From single-frame curb detections to the curb features the matcher uses (paper 2.2.1):
// multi-frame accumulation with odometry (Eq. 4-5), rejection of curbs next to obstacles (d_o), and
// the beam model that keeps a clean contour (Eq. 6-7).
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"

namespace lidarloop {

struct CurbFeatureParams {
  int frames = 5;                  // n in Eq. 4: this frame and the n - 1 before it
  double obstacle_distance = 0.5;  // d_o (Table I), m
  int beams = 36;                  // n_b (Table I): bins of 2 pi / n_b (the full-circle reading of Eq. 6)
  double beam_half_extent = 25.0;  // m: the +-25 m box of Eq. 6
};

// Eq. 5: where points of the previous vehicle frame are in the current one: R(-dpsi) (C - d), with
// `motion` = (d, dpsi) the vehicle's motion since the previous frame, in the previous vehicle frame
// (relative(previous pose, current pose)). The paper prints R(dpsi); with dpsi the vehicle's own turn,
// the points turn the other way.
std::vector<Eigen::Vector2d> to_current_frame(const std::vector<Eigen::Vector2d>& previous, const Pose2d& motion);
// The same in place (no copy of a frame that is moved every scan).
void move_to_current_frame(std::vector<Eigen::Vector2d>& points, const Pose2d& motion);

// Eq. 4: the last `frames` frames of curbs, kept in the current vehicle frame, with the positions the
// vehicle had at each of them (the launching points of the beam model).
class CurbAccumulator {
 public:
  explicit CurbAccumulator(int frames) : frames_(frames) {}
  void add(const std::vector<Eigen::Vector2d>& curbs, const Pose2d& motion_since_previous);
  std::vector<Eigen::Vector2d> curbs() const;
  const std::deque<Eigen::Vector2d>& launch_points() const { return origins_; }

 private:
  int frames_;
  std::deque<std::vector<Eigen::Vector2d>> history_;  // newest first
  std::deque<Eigen::Vector2d> origins_;               // vehicle positions of those frames, newest first
};

// Curbs within d_o of any obstacle point are the feet of cars and people, not curbs. Non-finite
// obstacle points are ignored; d_o <= 0 keeps every curb.
std::vector<Eigen::Vector2d> reject_near_obstacles(const std::vector<Eigen::Vector2d>& curbs,
                                                   const std::vector<Eigen::Vector2d>& obstacles, double distance);

// Eq. 6-7: from each launching point, the nearest curb in each of n_b angular bins inside the box;
// the union over launching points, without repeats, in a deterministic order.
std::vector<Eigen::Vector2d> beam_model(const std::vector<Eigen::Vector2d>& curbs,
                                        const std::deque<Eigen::Vector2d>& launch_points, const CurbFeatureParams& p);

}  // namespace lidarloop
