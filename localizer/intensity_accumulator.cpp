#include "localizer/intensity_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "localizer/curb_features.hpp"

namespace lidarloop {

IntensityAccumulator::IntensityAccumulator(int frames, double max_turn_rad)
    : frames_(frames), max_turn_rad_(max_turn_rad) {
  if (frames < 1) throw std::invalid_argument("IntensityAccumulator: frames must be at least 1");
  if (!(max_turn_rad >= 0)) throw std::invalid_argument("IntensityAccumulator: max_turn_rad must be >= 0");
}

void IntensityAccumulator::add(const std::vector<Eigen::Vector2d>& ground, const std::vector<double>& intensities,
                               const Pose2d& motion) {
  if (ground.size() != intensities.size())
    throw std::invalid_argument("IntensityAccumulator::add: " + std::to_string(ground.size()) + " points but " +
                                std::to_string(intensities.size()) + " intensities");
  for (Frame& frame : history_) {
    frame.ground = to_current_frame(frame.ground, motion);  // Eq. 5
    frame.turn_rad += motion.yaw;
  }
  history_.push_front({ground, intensities, 0.0});
  // The newest frames turned least: drop from the back while too many or turned too far.
  while (int(history_.size()) > frames_ || std::abs(history_.back().turn_rad) > max_turn_rad_) history_.pop_back();
}

IntensityGrid IntensityAccumulator::grid(const Pose2d& pose, const IntensityGridParams& params, int min_count) const {
  std::vector<Eigen::Vector3d> all;
  std::vector<double> intensities;
  all.reserve(points());
  intensities.reserve(points());
  for (const Frame& frame : history_) {
    for (const Eigen::Vector2d& p : frame.ground) all.emplace_back(p.x(), p.y(), 0.0);
    intensities.insert(intensities.end(), frame.intensities.begin(), frame.intensities.end());
  }
  IntensityGrid S = build_intensity_grid(all, intensities, pose, params);
  if (history_.empty()) return S;
  const size_t newest_points = history_.front().ground.size();
  const IntensityGrid newest =
      build_intensity_grid({all.begin(), all.begin() + long(newest_points)},
                           {intensities.begin(), intensities.begin() + long(newest_points)}, pose, params);
  const auto usable = [min_count](const IntensityGrid& g) {
    return std::count_if(g.cells.begin(), g.cells.end(),
                         [min_count](const IntensityCell& c) { return c.count > uint32_t(std::max(min_count, 0)); });
  };
  const auto newest_cells = usable(newest);
  if (newest_cells > 0) S.redundancy = std::max(1.0, double(usable(S)) / double(newest_cells));
  return S;
}

size_t IntensityAccumulator::points() const {
  size_t n = 0;
  for (const Frame& frame : history_) n += frame.ground.size();
  return n;
}

}  // namespace lidarloop
