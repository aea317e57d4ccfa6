// Grid S from several scans (intensity_accumulator.hpp): older frames moved by odometry (Eq. 5) land
// on the same ground, dashes sampled by different rings fill in, a bend drops the older frames, and
// the redundancy counts the extra cells.
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "localizer/intensity_accumulator.hpp"

namespace lidarloop {
namespace {

constexpr double kPaint = 200, kAsphalt = 20;
constexpr int kMinCount = 3;  // APS's n_e

// A world with one dash of paint: x in [10, 13), y in [-0.2, 0.2) (whole cells of S); asphalt elsewhere.
double world_intensity(const Eigen::Vector2d& p) {
  return p.x() >= 10 && p.x() < 13 && p.y() >= -0.2 && p.y() < 0.2 ? kPaint : kAsphalt;
}

// What a car at `position` (heading `yaw`) sees: "rings" at the given forward distances, each a row of
// points across y in [-1, 1) every 2 cm, as vehicle-frame points with the world's intensities.
void scan(const Eigen::Vector2d& position, double yaw, const std::vector<double>& rings,
          std::vector<Eigen::Vector2d>& points, std::vector<double>& intensities) {
  points.clear();
  intensities.clear();
  const Eigen::Rotation2Dd to_world(yaw);
  for (double x : rings)
    for (double y = -1.0; y < 1.0; y += 0.02) {
      const Eigen::Vector2d vehicle(x, y);
      points.push_back(vehicle);
      intensities.push_back(world_intensity(position + to_world * vehicle));
    }
}

IntensityGridParams grid_params() {
  IntensityGridParams p;
  p.width_cells = p.height_cells = 200;
  p.cell_m = 0.2;
  return p;
}

// Column of S holding vehicle-frame x.
int column(double x, const IntensityGridParams& p) { return int(std::floor(x / p.cell_m + 0.5 * p.width_cells)); }
int row(double y, const IntensityGridParams& p) { return int(std::floor(y / p.cell_m + 0.5 * p.height_cells)); }

TEST(IntensityAccumulator, OlderFramesLandWhereTheirGroundIsNow) {
  // The car drives 0.5 m per scan along x; each scan has rings 1 m apart. After five scans the dash's
  // far end (world x = 13) is sampled every ~0.5 m instead of every 1 m, and every painted cell of S is
  // where the dash is relative to the car now.
  const IntensityGridParams p = grid_params();
  IntensityAccumulator acc(5, 1.0);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> intensities;
  Eigen::Vector2d position(0, 0);
  for (int k = 0; k < 5; ++k) {
    const Pose2d step{k == 0 ? 0.0 : 0.5, 0.0, 0.0};
    position.x() += step.x;
    scan(position, 0.0, {5.05, 6.05, 7.05, 8.05, 9.05, 10.05, 11.05, 12.05}, points, intensities);
    acc.add(points, intensities, step);
  }
  const IntensityGrid S = acc.grid({}, p, kMinCount);
  int painted = 0;
  for (int r = 0; r < p.height_cells; ++r)
    for (int c = 0; c < p.width_cells; ++c) {
      const IntensityCell& cell = S.at(c, r);
      if (cell.count == 0) continue;
      const Eigen::Vector2d centre = S.cell_centre(c, r);
      const bool paint_here = world_intensity(position + centre) == kPaint;
      // A cell is paint exactly when the dash lies under it now (no cell straddles its edges here).
      EXPECT_EQ(cell.mean > 0.5 * (kPaint + kAsphalt), paint_here) << "cell centre " << centre.transpose();
      painted += cell.mean > 0.5 * (kPaint + kAsphalt);
    }
  // The dash now spans vehicle x in [8, 11): the newest scan's rings cross it at x = 8.05, 9.05, 10.05
  // (3 columns of 2 painted cells), the five scans' at every half metre (6 columns).
  EXPECT_EQ(painted, 12);
  // The newest scan alone puts its rings into 8 columns; the five together into more (their rings are
  // half a metre apart after the motion).
  EXPECT_GT(S.redundancy, 1.5);
}

TEST(IntensityAccumulator, OneFrameIsOneScan) {
  const IntensityGridParams p = grid_params();
  IntensityAccumulator acc(1, 1.0);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> intensities;
  scan({0, 0}, 0.0, {5.05, 6.05}, points, intensities);
  acc.add(points, intensities, {});
  scan({1, 0}, 0.0, {5.05, 6.05}, points, intensities);
  acc.add(points, intensities, {1.0, 0.0, 0.0});
  EXPECT_EQ(acc.points(), points.size());
  const IntensityGrid S = acc.grid({}, p, kMinCount);
  EXPECT_DOUBLE_EQ(S.redundancy, 1.0);
  EXPECT_GT(S.at(column(5.05, p), row(0.0, p)).count, 0u);
}

TEST(IntensityAccumulator, ABendDropsTheOlderFrames) {
  // Turning 0.3 deg per scan with a limit of 0.5 deg: only the newest frame and the one before stay
  // (0.3 deg since it); the others have turned 0.6 deg and more.
  IntensityAccumulator acc(5, 0.5 * 3.14159265358979 / 180);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> intensities;
  for (int k = 0; k < 5; ++k) {
    scan({0, 0}, 0.0, {5.05}, points, intensities);
    acc.add(points, intensities, {0.5, 0.0, k == 0 ? 0.0 : 0.3 * 3.14159265358979 / 180});
  }
  EXPECT_EQ(acc.points(), 2 * points.size());
}

TEST(IntensityAccumulator, SSaysWhenTheLastScanTurnedBeyondTheLimit) {
  const IntensityGridParams p = grid_params();
  const double limit = 0.5 * 3.14159265358979 / 180;
  IntensityAccumulator acc(5, limit);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> intensities;
  scan({0, 0}, 0.0, {5.05}, points, intensities);
  acc.add(points, intensities, {0.5, 0.0, 0.9 * limit});
  EXPECT_FALSE(acc.grid({}, p, kMinCount).turning);
  acc.add(points, intensities, {0.5, 0.0, -1.1 * limit});  // a right turn counts as well
  EXPECT_TRUE(acc.grid({}, p, kMinCount).turning);
  acc.add(points, intensities, {0.5, 0.0, 0.0});
  EXPECT_FALSE(acc.grid({}, p, kMinCount).turning);
}

TEST(IntensityAccumulator, AnEmptyScanKeepsTheOlderFramesInPlace) {
  const IntensityGridParams p = grid_params();
  IntensityAccumulator acc(3, 1.0);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> intensities;
  scan({0, 0}, 0.0, {5.05}, points, intensities);
  acc.add(points, intensities, {});
  acc.add({}, {}, {1.0, 0.0, 0.0});  // the car moved 1 m and saw nothing
  const IntensityGrid S = acc.grid({}, p, kMinCount);
  EXPECT_GT(S.at(column(4.05, p), row(0.0, p)).count, 0u);  // the ring is 1 m nearer now
  EXPECT_EQ(S.at(column(5.05, p), row(0.0, p)).count, 0u);
  EXPECT_DOUBLE_EQ(S.redundancy, 1.0);  // the newest frame has no cells: nothing to compare with
}

TEST(IntensityAccumulator, BadInputIsRefused) {
  EXPECT_THROW(IntensityAccumulator(0, 1.0), std::invalid_argument);
  EXPECT_THROW(IntensityAccumulator(5, -1.0), std::invalid_argument);
  IntensityAccumulator acc(5, 1.0);
  EXPECT_THROW(acc.add({Eigen::Vector2d(1, 0)}, {}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace lidarloop
