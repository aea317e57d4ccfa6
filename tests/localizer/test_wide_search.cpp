// Wide APS over x, y and yaw (wide_search.hpp): recovery of a known (4 m, -3 m, 3 deg) error on
// non-periodic paint, a small margin between the peaks of stripes that repeat every 3 m, the search
// spread over steps giving the one-shot answer, and refusal of mismatched cells.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "localizer/wide_search.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr double kResolution = 0.2;  // the map's cells and S's (Table I scale)
constexpr double kDeg = std::numbers::pi / 180.0;
const Geodetic kCampus{31.2856, 121.2147, 4.0};

// The mapped area, and S: 100 x 100 cells (20 m), smaller than Table I's so the test stays short under
// the sanitizers; the search does not depend on S's size.
constexpr double kMapHalf = 24.0;
constexpr int kSCells = 100;
constexpr int kMapSamplesPerCell = 6;   // a mapping drive's points per cell
constexpr int kScanSamplesPerCell = 6;  // more than n_e = 3, so most cells of S take part
constexpr double kPaint = 35, kPaintNoise = 4, kAsphalt = 6, kAsphaltNoise = 1.5;  // intensity counts

// Paint as rectangles [x0, x1] x [y0, y1].
struct Rect {
  double x0, x1, y0, y1;
};
using Paint = std::vector<Rect>;

bool painted(const Paint& paint, const Eigen::Vector2d& p) {
  for (const Rect& r : paint)
    if (p.x() >= r.x0 && p.x() <= r.x1 && p.y() >= r.y0 && p.y() <= r.y1) return true;
  return false;
}

// Lane edges, a centre line of dashes of uneven lengths, and arrows and patches placed at random: no
// shift of a few metres maps it onto itself.
Paint irregular_paint() {
  Paint paint{{-kMapHalf, kMapHalf, -3.6, -3.45}, {-kMapHalf, kMapHalf, 3.45, 3.6}};
  double x = -kMapHalf;
  for (double dash : {2.0, 3.5, 1.5, 4.0, 2.5, 3.0, 1.0, 3.5, 2.0, 4.5, 1.5, 3.0, 2.5})
    paint.push_back({x, x + dash, -0.08, 0.08}), x += dash + 2.7;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> where(-kMapHalf, kMapHalf), size(0.4, 2.5);
  for (int k = 0; k < 30; ++k) {
    const double x0 = where(rng), y0 = where(rng);
    paint.push_back({x0, x0 + size(rng), y0, y0 + size(rng)});
  }
  return paint;
}

// Stripes 0.6 m wide across the road every 3 m along it, between two lane edges: any shift by 3 m
// along x fits as well as the truth.
constexpr double kStripePeriod = 3.0;
Paint stripes() {
  Paint paint{{-kMapHalf, kMapHalf, -3.6, -3.45}, {-kMapHalf, kMapHalf, 3.45, 3.6}};
  for (double x = -kMapHalf; x < kMapHalf; x += kStripePeriod) paint.push_back({x, x + 0.6, -3.0, 3.0});
  return paint;
}

// A margin of log P below which two places fit alike here: the aliases of the stripes differ by the
// noise of ~8000 cells and by where the map's cells fall under S's at each (tens), unique paint by
// thousands.
constexpr double kAmbiguousMargin = 100.0;

double intensity(const Paint& paint, const Eigen::Vector2d& p, std::mt19937& rng) {
  const bool paint_here = painted(paint, p);
  std::normal_distribution<double> noise(0.0, paint_here ? kPaintNoise : kAsphaltNoise);
  return (paint_here ? kPaint : kAsphalt) + noise(rng);
}

std::string build_map(const Paint& paint, const std::string& name) {
  IntensityMapHeader h;
  h.world = "wide_search_test";
  h.world_hash = "0123456789abcdef";
  h.origin = kCampus;
  h.resolution_m = kResolution;
  IntensityMapBuilder builder(h);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-kMapHalf, kMapHalf);
  const int points = int(std::pow(2 * kMapHalf / kResolution, 2)) * kMapSamplesPerCell;
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector2d p(u(rng), u(rng));
    builder.add(p, intensity(paint, p, rng));
  }
  const fs::path dir = fs::path(::testing::TempDir()) / ("lidarloop_wide_" + name + "_" + std::to_string(::getpid()));
  builder.save(dir.string());
  return dir.string();
}

IntensityGridParams grid_params() {
  IntensityGridParams g;
  g.width_cells = g.height_cells = kSCells;
  return g;
}

// S of the ground seen from `truth`, placed at `prior`.
IntensityGrid scan(const Paint& paint, const Pose2d& truth, const Pose2d& prior, uint32_t seed) {
  const IntensityGridParams g = grid_params();
  std::mt19937 rng(seed);
  const double half = 0.5 * kSCells * kResolution;
  std::uniform_real_distribution<double> u(-half, half);
  std::vector<Eigen::Vector3d> points;
  std::vector<double> values;
  for (int i = 0; i < kSCells * kSCells * kScanSamplesPerCell; ++i) {
    const Eigen::Vector2d v(u(rng), u(rng));
    const Eigen::Vector2d world = truth.apply(v);
    if (std::fabs(world.x()) > kMapHalf || std::fabs(world.y()) > kMapHalf) continue;
    points.emplace_back(v.x(), v.y(), 0.0);
    values.push_back(intensity(paint, world, rng));
  }
  return build_intensity_grid(points, values, prior, g);
}

// The truth, and a prior it is (4 m, -3 m, 3 deg) from in the prior's vehicle frame.
const Pose2d kTruth{1.0, -0.5, 20.0 * kDeg};
const Pose2d kError{4.0, -3.0, 3.0 * kDeg};
const Pose2d kPrior = kTruth.compose(kError.inverse());

// Each map is built on first use: CTest runs every test case in a process of its own.
class WideSearch : public ::testing::Test {
 protected:
  static const std::string& irregular_dir() { return dir(irregular_dir_, irregular_paint(), "irregular"); }
  static const std::string& stripes_dir() { return dir(stripes_dir_, stripes(), "stripes"); }
  static void TearDownTestSuite() {
    for (std::string** d : {&irregular_dir_, &stripes_dir_}) {
      if (*d) fs::remove_all(**d);
      delete *d;
      *d = nullptr;
    }
  }

 private:
  static const std::string& dir(std::string*& d, const Paint& paint, const std::string& name) {
    if (!d) d = new std::string(build_map(paint, name));
    return *d;
  }
  static std::string* irregular_dir_;
  static std::string* stripes_dir_;
};
std::string* WideSearch::irregular_dir_ = nullptr;
std::string* WideSearch::stripes_dir_ = nullptr;

TEST_F(WideSearch, RecoversAKnownErrorOfMetresAndDegrees) {
  IntensityMap map(irregular_dir());
  const IntensityGrid S = scan(irregular_paint(), kTruth, kPrior, 3);
  const auto start = std::chrono::steady_clock::now();
  const WideApsResult r = wide_aps_search(S, map);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "[ wide ] pose (%.3f, %.3f, %.2f deg), truth (%.3f, %.3f, %.2f deg); std (%.3f, %.3f m, %.2f deg); "
      "margin %.1f; %d cells; %lld offsets, %lld terms; %.1f ms\n",
      r.pose.x, r.pose.y, r.pose.yaw / kDeg, kTruth.x, kTruth.y, kTruth.yaw / kDeg, std::sqrt(r.covariance(0, 0)),
      std::sqrt(r.covariance(1, 1)), std::sqrt(r.covariance(2, 2)) / kDeg, r.margin, r.cells_used,
      (long long)r.offsets_evaluated, (long long)r.terms_evaluated, ms);
  ASSERT_TRUE(r.ok);
  EXPECT_LT(std::hypot(r.pose.x - kTruth.x, r.pose.y - kTruth.y), kResolution);
  EXPECT_LT(std::fabs(wrap_angle(r.pose.yaw - kTruth.yaw)), 0.5 * kDeg);
  // The correction moves the prior to the pose.
  const Pose2d moved = r.correction.compose(kPrior);
  EXPECT_NEAR(moved.x, r.pose.x, 1e-9);
  EXPECT_NEAR(moved.y, r.pose.y, 1e-9);
  EXPECT_FALSE(r.peak_on_edge);
  // Nothing else in the window fits nearly as well, and the spread is honest: sub-cell, sub-degree.
  EXPECT_GT(r.margin, 10 * kAmbiguousMargin);
  EXPECT_LT(std::sqrt(r.covariance(0, 0)), kResolution);
  EXPECT_LT(std::sqrt(r.covariance(2, 2)), 0.5 * kDeg);
  EXPECT_GE(r.cells_used, ApsParams{}.min_cells);
}

TEST_F(WideSearch, PeriodicStripesLeaveASmallMarginAlongTheRoad) {
  IntensityMap map(stripes_dir());
  const IntensityGrid S = scan(stripes(), kTruth, kPrior, 4);
  const WideApsResult r = wide_aps_search(S, map);
  std::printf("[ wide ] stripes: pose (%.3f, %.3f), runner-up (%.3f, %.3f); margin %.2f\n", r.pose.x, r.pose.y,
              r.runner_up.x, r.runner_up.y, r.margin);
  ASSERT_TRUE(r.ok);
  // The runner-up is a whole number of periods (3 m) along the stripes' normal (local x) from the
  // best, and fits nearly as well: a margin of tens where unique paint has thousands (the test above).
  const double periods = std::fabs(r.runner_up.x - r.pose.x) / kStripePeriod;
  EXPECT_GE(std::lround(periods), 1);
  EXPECT_LT(std::fabs(periods - std::round(periods)) * kStripePeriod, 2 * kResolution);
  EXPECT_LT(std::fabs(r.runner_up.y - r.pose.y), 2 * kResolution);
  EXPECT_LT(r.margin, kAmbiguousMargin);
}

TEST_F(WideSearch, SpreadOverStepsGivesTheOneShotAnswer) {
  IntensityMap map(irregular_dir());
  const IntensityGrid S = scan(irregular_paint(), kTruth, kPrior, 5);
  const WideApsResult once = wide_aps_search(S, map);
  WideApsParams p;
  p.max_terms_per_step = 200'000;  // a share of a coarse slice's or a refinement's work
  WideApsSearch search(p);
  int steps = 0;
  while (!search.done() && steps < 1000) {
    EXPECT_FALSE(search.result().ok);
    search.step(S, map);
    ++steps;
  }
  ASSERT_TRUE(search.done());
  EXPECT_GT(steps, 10);  // one unit per step
  const WideApsResult& r = search.result();
  ASSERT_TRUE(r.ok);
  EXPECT_DOUBLE_EQ(r.pose.x, once.pose.x);
  EXPECT_DOUBLE_EQ(r.pose.y, once.pose.y);
  EXPECT_DOUBLE_EQ(r.pose.yaw, once.pose.yaw);
  EXPECT_DOUBLE_EQ(r.margin, once.margin);
  EXPECT_EQ(r.offsets_evaluated, once.offsets_evaluated);
  search.step(S, map);  // done: nothing more
  EXPECT_EQ(search.result().offsets_evaluated, once.offsets_evaluated);
  search.restart();
  EXPECT_FALSE(search.done());
  EXPECT_FALSE(search.result().ok);
}

// The car drives on between steps and the prior follows it with odometry: what earlier steps found,
// kept as corrections of the prior, still leads to the truth at the last step's prior.
TEST_F(WideSearch, SpreadOverStepsFollowsAMovingPrior) {
  IntensityMap map(irregular_dir());
  WideApsParams p;
  p.max_terms_per_step = 500'000;
  WideApsSearch search(p);
  const Pose2d motion{0.3, 0.0, 0.2 * kDeg};  // one scan's odometry
  Pose2d truth = kTruth, prior = kPrior;
  int steps = 0;
  while (!search.done() && steps < 200) {
    search.step(scan(irregular_paint(), truth, prior, 10 + uint32_t(steps)), map);
    truth = truth.compose(motion);
    prior = prior.compose(motion);
    ++steps;
  }
  ASSERT_TRUE(search.done());
  const WideApsResult& r = search.result();
  ASSERT_TRUE(r.ok);
  // The result is at the last step's prior, the step before the last motion.
  const Pose2d last_truth = truth.compose(motion.inverse());
  EXPECT_LT(std::hypot(r.pose.x - last_truth.x, r.pose.y - last_truth.y), kResolution) << steps << " steps";
  EXPECT_LT(std::fabs(wrap_angle(r.pose.yaw - last_truth.yaw)), 0.5 * kDeg);
}

TEST_F(WideSearch, RefusesBadInput) {
  IntensityMap map(irregular_dir());
  IntensityGrid S = scan(irregular_paint(), kTruth, kPrior, 6);
  WideApsParams p;
  p.coarse_factor = 3;  // 100 cells are not whole 3-cell blocks
  EXPECT_THROW(wide_aps_search(S, map, p), std::invalid_argument);
  p = {};
  p.fine_yaw_step_rad = 0;
  EXPECT_THROW(WideApsSearch{p}, std::invalid_argument);
  S.params.cell_m = 0.25;  // not the map's cells
  EXPECT_THROW(wide_aps_search(S, map), std::invalid_argument);
  // An empty S has no usable cells: no estimate.
  const IntensityGrid empty = build_intensity_grid({}, {}, kPrior, grid_params());
  EXPECT_FALSE(wide_aps_search(empty, map).ok);
}

}  // namespace
}  // namespace lidarloop
