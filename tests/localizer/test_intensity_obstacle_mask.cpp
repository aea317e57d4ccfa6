// Ground points near obstacles stay out of S (IntensityGridParams::obstacle_distance): which cells of S
// lie within the distance of an obstacle point, by their centres.
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include "localizer/aps_matcher.hpp"

namespace lidarloop {
namespace {

IntensityGridParams params(double distance) {
  IntensityGridParams p;
  p.width_cells = p.height_cells = 100;  // +-10 m at 0.2 m
  p.cell_m = 0.2;
  p.obstacle_distance = distance;
  return p;
}

bool near(const std::vector<char>& mask, const IntensityGridParams& p, const Eigen::Vector2d& at) {
  return mask.at(*intensity_cell_index(p, at)) != 0;
}

TEST(IntensityObstacleMask, CellsWithinTheDistanceOfAnObstacleAreMarked) {
  const IntensityGridParams p = params(0.5);
  // An obstacle point on a cell centre (5.1, 0.1): cell centres 0.4 m off are marked, 0.6 m off are not.
  const std::vector<char> mask = cells_near_obstacles({{5.1, 0.1}}, p);
  EXPECT_TRUE(near(mask, p, {5.1, 0.1}));
  EXPECT_TRUE(near(mask, p, {5.5, 0.1}));
  EXPECT_TRUE(near(mask, p, {5.1, -0.3}));
  EXPECT_TRUE(near(mask, p, {5.3, 0.5}));   // 0.2, 0.4: 0.45 m
  EXPECT_FALSE(near(mask, p, {5.5, 0.5}));  // 0.4, 0.4: 0.57 m
  EXPECT_FALSE(near(mask, p, {5.7, 0.1}));
  EXPECT_FALSE(near(mask, p, {4.5, 0.1}));
  // Cells within 0.5 m of a point on a cell centre: the centres on a 0.2 m lattice within 2.5 steps.
  int marked = 0;
  for (char m : mask) marked += m;
  EXPECT_EQ(marked, 21);
}

TEST(IntensityObstacleMask, MarksExactlyTheCellsWhoseCentresAreWithinTheDistance) {
  // Random obstacles, some off the grid, and a dense row of them, against the definition cell by cell.
  for (double distance : {0.5, 0.33, 1.0}) {
    const IntensityGridParams p = params(distance);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> coordinate(-10.6, 10.6);
    std::vector<Eigen::Vector2d> obstacles;
    for (int k = 0; k < 300; ++k) obstacles.push_back({coordinate(rng), coordinate(rng)});
    // And a car's side: many points to a cell, as a parked row returns them.
    std::uniform_real_distribution<double> along(3.0, 7.5), across(-2.1, -1.7);
    for (int k = 0; k < 1500; ++k) obstacles.push_back({along(rng), across(rng)});
    const std::vector<char> mask = cells_near_obstacles(obstacles, p);
    for (int r = 0; r < p.height_cells; ++r)
      for (int c = 0; c < p.width_cells; ++c) {
        const Eigen::Vector2d centre((c + 0.5 - 0.5 * p.width_cells) * p.cell_m,
                                     (r + 0.5 - 0.5 * p.height_cells) * p.cell_m);
        bool expected = false;
        for (const Eigen::Vector2d& o : obstacles) expected |= (centre - o).squaredNorm() <= distance * distance;
        ASSERT_EQ(mask[size_t(r) * size_t(p.width_cells) + size_t(c)] != 0, expected)
            << "cell " << c << ", " << r << " at distance " << distance;
      }
  }
}

TEST(IntensityObstacleMask, AnObstacleJustOffTheGridStillMarksTheEdge) {
  const IntensityGridParams p = params(0.5);
  const std::vector<char> mask = cells_near_obstacles({{10.2, 0.1}}, p);  // 0.2 m beyond the front edge
  EXPECT_TRUE(near(mask, p, {9.9, 0.1}));                                 // the last column's centre: 0.3 m
  EXPECT_FALSE(near(mask, p, {9.5, 0.1}));                                // 0.7 m
}

TEST(IntensityObstacleMask, ZeroDistanceOrNoObstaclesMarkNothing) {
  for (const std::vector<char>& mask :
       {cells_near_obstacles({{5.1, 0.1}}, params(0.0)), cells_near_obstacles({}, params(0.5)),
        cells_near_obstacles({{1e9, 0.0}, {NAN, 0.0}}, params(0.5))}) {
    int marked = 0;
    for (char m : mask) marked += m;
    EXPECT_EQ(marked, 0);
  }
}

}  // namespace
}  // namespace lidarloop
