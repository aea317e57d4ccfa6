#include "localizer/curb_features.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Geometry>
#include "localizer/map_index.hpp"
#include "localizer/probabilistic_icp.hpp"

namespace lidarloop {

void move_to_current_frame(std::vector<Eigen::Vector2d>& points, const Pose2d& m) {
  // In place: S's older frames (tens of thousands of points) are moved every scan, and a new vector
  // each time was an allocation and a copy. The matrix is Rotation2D's own, so the product is the same.
  const Eigen::Matrix2d back = Eigen::Rotation2D<double>(-m.yaw).toRotationMatrix();
  const Eigen::Vector2d d(m.x, m.y);
  for (auto& c : points) c = back * (c - d);
}

std::vector<Eigen::Vector2d> to_current_frame(const std::vector<Eigen::Vector2d>& previous, const Pose2d& m) {
  std::vector<Eigen::Vector2d> out(previous);
  move_to_current_frame(out, m);
  return out;
}

void CurbAccumulator::add(const std::vector<Eigen::Vector2d>& curbs, const Pose2d& motion) {
  for (auto& frame : history_) move_to_current_frame(frame, motion);
  const std::vector<Eigen::Vector2d> moved =
      to_current_frame(std::vector<Eigen::Vector2d>(origins_.begin(), origins_.end()), motion);
  origins_.assign(moved.begin(), moved.end());
  history_.push_front(curbs);
  origins_.push_front(Eigen::Vector2d::Zero());
  while (int(history_.size()) > frames_) history_.pop_back(), origins_.pop_back();
}

std::vector<Eigen::Vector2d> CurbAccumulator::curbs() const {
  std::vector<Eigen::Vector2d> all;
  for (const auto& frame : history_) all.insert(all.end(), frame.begin(), frame.end());
  return all;
}

std::vector<Eigen::Vector2d> reject_near_obstacles(const std::vector<Eigen::Vector2d>& curbs,
                                                   const std::vector<Eigen::Vector2d>& obstacles, double distance) {
  std::vector<Eigen::Vector2d> finite;
  finite.reserve(obstacles.size());
  for (const auto& o : obstacles)
    if (o.allFinite()) finite.push_back(o);
  if (finite.empty() || !(distance > 0)) return curbs;
  // Buckets only: between parked rows there are thousands of obstacle points a scan against a few
  // hundred curbs, and a KD-tree over them cost more than the questions (MapIndex::Queries).
  const MapIndex index(std::move(finite), distance, MapIndex::Queries::within_only);
  std::vector<Eigen::Vector2d> kept;
  for (const auto& c : curbs)
    if (index.nearest_within(c, distance).first == SIZE_MAX) kept.push_back(c);
  return kept;
}

std::vector<Eigen::Vector2d> beam_model(const std::vector<Eigen::Vector2d>& curbs,
                                        const std::deque<Eigen::Vector2d>& launch_points, const CurbFeatureParams& p) {
  const double bin = 2 * M_PI / p.beams;  // delta = 2 pi / n_b
  std::set<size_t> chosen;
  for (const Eigen::Vector2d& origin : launch_points) {
    std::vector<std::pair<double, size_t>> nearest(size_t(p.beams), {INFINITY, 0});
    for (size_t i = 0; i < curbs.size(); ++i) {
      const Eigen::Vector2d v = curbs[i] - origin;
      if (std::abs(v.x()) > p.beam_half_extent || std::abs(v.y()) > p.beam_half_extent) continue;  // Eq. 6 box
      const double angle = std::atan2(v.y(), v.x()) + M_PI;                                        // [0, 2 pi]
      const size_t k = std::min(size_t(angle / bin), size_t(p.beams) - 1);
      const double r = v.norm();
      if (r < nearest[k].first) nearest[k] = {r, i};  // Eq. 7: the shortest distance in the beam
    }
    for (const auto& [r, i] : nearest)
      if (std::isfinite(r)) chosen.insert(i);
  }
  std::vector<Eigen::Vector2d> out;
  for (size_t i : chosen) out.push_back(curbs[i]);
  return out;
}

}  // namespace lidarloop
