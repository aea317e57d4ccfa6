#include "localizer/intensity_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "localizer/curb_features.hpp"

namespace lidarloop {

IntensityAccumulator::IntensityAccumulator(int frames, double max_turn_rad)
    : frames_(frames), max_turn_rad_(max_turn_rad) {
  if (frames < 1) throw std::invalid_argument("IntensityAccumulator: frames must be at least 1");
  if (!(max_turn_rad >= 0)) throw std::invalid_argument("IntensityAccumulator: max_turn_rad must be >= 0");
}

void IntensityAccumulator::add(std::vector<Eigen::Vector2d> ground, std::vector<double> intensities,
                               const Pose2d& motion) {
  if (ground.size() != intensities.size())
    throw std::invalid_argument("IntensityAccumulator::add: " + std::to_string(ground.size()) + " points but " +
                                std::to_string(intensities.size()) + " intensities");
  last_turn_rad_ = motion.yaw;
  for (Frame& frame : history_) {
    move_to_current_frame(frame.ground, motion);  // Eq. 5
    frame.turn_rad += motion.yaw;
  }
  history_.push_front({std::move(ground), std::move(intensities), 0.0});
  // The newest frames turned least: drop from the back while too many or turned too far.
  while (int(history_.size()) > frames_ || std::abs(history_.back().turn_rad) > max_turn_rad_) history_.pop_back();
}

IntensityGrid IntensityAccumulator::grid(const Pose2d& pose, const IntensityGridParams& params, int min_count) const {
  IntensityGridBuilder builder(pose, params);
  const uint32_t n_e = uint32_t(std::max(min_count, 0));
  long newest_cells = 0;
  for (const Frame& frame : history_) {  // newest first
    builder.add(frame.ground, frame.intensities);
    if (&frame == &history_.front()) newest_cells = builder.cells_with_more_than(n_e);
  }
  IntensityGrid S = builder.grid();
  S.turning = std::abs(last_turn_rad_) > max_turn_rad_;
  if (newest_cells > 0) S.redundancy = std::max(1.0, double(builder.cells_with_more_than(n_e)) / double(newest_cells));
  return S;
}

size_t IntensityAccumulator::points() const {
  size_t n = 0;
  for (const Frame& frame : history_) n += frame.ground.size();
  return n;
}

}  // namespace lidarloop
