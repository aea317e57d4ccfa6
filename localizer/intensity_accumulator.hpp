#pragma once
// Grid S from the ground of several scans (beyond the paper, which builds S from one): the paper's own
// multi-frame accumulation of curbs (Eq. 4-5: the last n frames, moved into the current vehicle frame
// by odometry) applied to the road's intensities.
//
// Why: the HDL-32E's rings fall on the ground about 1 m apart at 10 m (1.33 deg between lasers seen
// from 1.9 m up), and S's cells only take part with more than n_e points (Eq. 14), so one scan sees a
// dash's end only where a ring happens to cross it: along a road with nothing but a dashed line, APS's
// longitudinal estimate from one scan wandered by a metre (cold_start_parked). The rings move with the
// car, so five scans (0.5 s, 3 m at 6 m/s) cross each end several times, while CAN odometry drifts
// millimetres over that time.
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"
#include "localizer/aps_matcher.hpp"

namespace lidarloop {

class IntensityAccumulator {
 public:
  // `frames`: this scan and the frames - 1 before it (n of Eq. 4); at least 1. A frame is dropped early
  // once the car has turned more than `max_turn_rad` since it (see IntensityGridParams::max_turn_deg).
  IntensityAccumulator(int frames, double max_turn_rad);

  // One scan's ground points (vehicle frame; z is ignored) with their intensities on the map's scale;
  // `motion_since_previous` as Eq. 5 takes it (relative(previous pose, current pose)). An empty scan is
  // a frame too, so the older ones stay where they are relative to the car. Throws
  // std::invalid_argument for mismatched sizes.
  void add(std::vector<Eigen::Vector2d> ground, std::vector<double> intensities, const Pose2d& motion_since_previous);

  // S (Eq. 8) over all kept frames, placed at `pose` (the prior of the match), with its redundancy:
  // the cells with more than `min_count` points (APS's n_e) over those of the newest frame alone; and
  // whether the last motion turned the car beyond max_turn_rad (IntensityGrid::turning).
  IntensityGrid grid(const Pose2d& pose, const IntensityGridParams& params, int min_count) const;

  size_t points() const;

 private:
  struct Frame {
    std::vector<Eigen::Vector2d> ground;  // in the current vehicle frame
    std::vector<double> intensities;
    double turn_rad = 0;  // the car's heading change since this frame, by odometry
  };
  int frames_;
  double max_turn_rad_;
  std::deque<Frame> history_;  // newest first
  double last_turn_rad_ = 0;   // the heading change of the last motion added
};

}  // namespace lidarloop
