#pragma once
// Heights known at scattered points, blended into a surface: the terrain under a Lanelet2 map's points
// (sim/lanelet2_world.cpp), the ground beside an OpenDRIVE map's roads (sim/opendrive_world.cpp).
#include <vector>

#include <Eigen/Core>

#include "common/points_kd_tree.hpp"

namespace lidarloop {

// Modified Shepard weights (Franke & Nielson, 1980: w = ((R - d)+ / (R d))^2 over the k nearest, R the
// distance of the next one), which, unlike plain inverse distance weighting over k neighbours, stay
// continuous as the neighbours change. Moved here unchanged from sim/lanelet2_world.cpp.
class ScatteredHeights {
 public:
  static constexpr size_t kNeighbours = 8;  // points of known height blended

  ScatteredHeights(std::vector<Eigen::Vector2d> points, std::vector<double> z);
  ScatteredHeights(const ScatteredHeights&) = delete;
  ScatteredHeights& operator=(const ScatteredHeights&) = delete;
  double operator()(const Eigen::Vector2d& p) const;  // 0 with no points

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> z_;
  PointsKdTree tree_;
};

}  // namespace lidarloop
