// APS intensity matching (sections 2.2.2 and 3.2, Eq. 8 and 14-18): grid S binning, recovery of a
// known offset on a crosswalk with the vehicle turned 30 degrees, the limit of the search window, a
// broad distribution on a featureless road, refusal of too little data or mismatched cells, and the
// steps of the match on their own (search window, Eq. 14 in logs, peak on the edge, Eq. 15-16).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>

#include "localizer/aps_matcher.hpp"
#include "localizer/intensity_map.hpp"
#include "localizer/localizer_params.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr double kResolution = 0.2;  // the map's cells and S's (Table I scale)
const Geodetic kCampus{31.2856, 121.2147, 4.0};

// The mapped area: a 60 m x 20 m stretch of road along local x.
constexpr double kMapMinX = 0, kMapMaxX = 60, kMapMinY = -10, kMapMaxY = 10;
constexpr double kMapPointsPerCell = 25;   // a mapping drive passes several times
constexpr double kScanPointsPerCell = 10;  // one scan sees less

// A crosswalk: stripes 0.45 m wide every 1.05 m along the road, 6 m long across it. A finite number of
// stripes, so a shift by one period is not a match (the ends differ).
constexpr double kStripeWidth = 0.45, kStripePeriod = 1.05, kCrosswalkStartX = 26.0;
constexpr int kStripes = 8;
constexpr double kCrosswalkHalfLength = 3.0;
constexpr double kPaint = 35, kPaintNoise = 4, kAsphalt = 6, kAsphaltNoise = 1.5;  // intensity counts

// Truth and the error of the prior, in the vehicle frame (longitudinal, lateral).
const Pose2d kTruth{30.3, 0.1, 30.0 * std::numbers::pi / 180.0};
const Eigen::Vector2d kPriorError(1.2, -0.4);

using Pattern = bool (*)(const Eigen::Vector2d&);  // is there paint at this local point?

bool crosswalk(const Eigen::Vector2d& p) {
  if (std::fabs(p.y()) > kCrosswalkHalfLength) return false;
  const double u = p.x() - kCrosswalkStartX;
  if (u < 0 || u >= kStripes * kStripePeriod) return false;
  return std::fmod(u, kStripePeriod) < kStripeWidth;
}

bool plain_asphalt(const Eigen::Vector2d&) { return false; }

bool on_map(const Eigen::Vector2d& p) {
  return p.x() >= kMapMinX && p.x() < kMapMaxX && p.y() >= kMapMinY && p.y() < kMapMaxY;
}

double intensity(Pattern pattern, const Eigen::Vector2d& p, std::mt19937& rng) {
  const bool paint = pattern(p);
  std::normal_distribution<double> noise(0.0, paint ? kPaintNoise : kAsphaltNoise);
  return (paint ? kPaint : kAsphalt) + noise(rng);
}

Eigen::Matrix2d rotation(double yaw) {
  Eigen::Matrix2d r;
  r << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  return r;
}

// The pose a localizer would believe: the truth moved by `error` (vehicle frame) the wrong way, so the
// correct answer of the match is offset == error.
Pose2d prior_from(const Pose2d& truth, const Eigen::Vector2d& error) {
  const Eigen::Vector2d p = Eigen::Vector2d(truth.x, truth.y) - rotation(truth.yaw) * error;
  return {p.x(), p.y(), truth.yaw};
}

std::string build_map(Pattern pattern, const std::string& name, uint32_t seed) {
  IntensityMapHeader h;
  h.world = "aps_test";
  h.world_hash = "0123456789abcdef";
  h.origin = kCampus;
  h.resolution_m = kResolution;
  IntensityMapBuilder builder(h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(kMapMinX, kMapMaxX), uy(kMapMinY, kMapMaxY);
  const double area = (kMapMaxX - kMapMinX) * (kMapMaxY - kMapMinY);
  const int points = static_cast<int>(area / (kResolution * kResolution) * kMapPointsPerCell);
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    builder.add(p, intensity(pattern, p, rng));
  }
  const fs::path dir = fs::path(::testing::TempDir()) / ("lidarloop_aps_" + name + "_" + std::to_string(::getpid()));
  builder.save(dir.string());
  return dir.string();
}

// Ground points of one scan at `truth`, in the vehicle frame, over grid S and the mapped area.
struct Scan {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> intensities;
};

Scan scan_at(Pattern pattern, const Pose2d& truth, const IntensityGridParams& g, uint32_t seed) {
  Scan scan;
  std::mt19937 rng(seed);
  const double half_x = 0.5 * g.width_cells * g.cell_m, half_y = 0.5 * g.height_cells * g.cell_m;
  std::uniform_real_distribution<double> ux(-half_x, half_x), uy(-half_y, half_y);
  const int samples = static_cast<int>(double(g.width_cells) * g.height_cells * kScanPointsPerCell);
  const Eigen::Matrix2d R = rotation(truth.yaw);
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector2d v(ux(rng), uy(rng));
    const Eigen::Vector2d local = Eigen::Vector2d(truth.x, truth.y) + R * v;
    if (!on_map(local)) continue;  // the scan's ground outside the mapped road is not modelled
    scan.points.emplace_back(v.x(), v.y(), 0.0);
    scan.intensities.push_back(intensity(pattern, local, rng));
  }
  return scan;
}

// Local-frame covariance back in the vehicle frame (longitudinal, lateral).
Eigen::Matrix2d vehicle_covariance(const ApsResult& r, double yaw) {
  return rotation(yaw).transpose() * r.covariance * rotation(yaw);
}

// Position error in the vehicle frame (longitudinal, lateral).
Eigen::Vector2d vehicle_error(const ApsResult& r, const Pose2d& truth) {
  return rotation(truth.yaw).transpose() * (r.position - Eigen::Vector2d(truth.x, truth.y));
}

class Aps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    crosswalk_dir_ = new std::string(build_map(crosswalk, "crosswalk", 1));
    asphalt_dir_ = new std::string(build_map(plain_asphalt, "asphalt", 2));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*crosswalk_dir_);
    fs::remove_all(*asphalt_dir_);
    delete crosswalk_dir_;
    delete asphalt_dir_;
  }
  static std::string* crosswalk_dir_;
  static std::string* asphalt_dir_;
};
std::string* Aps::crosswalk_dir_ = nullptr;
std::string* Aps::asphalt_dir_ = nullptr;

// ---------------------------------------------------------------------------------------------------
// Grid S (Eq. 8)

TEST(ApsGrid, BinsPointsAroundTheVehicleAndKeepsRunningStatistics) {
  const IntensityGridParams g;  // 200 x 200 at 0.2 m: +-20 m
  const std::vector<Eigen::Vector3d> points{{0.1, 0.1, 0},   {0.15, 0.05, 0},  {0.19, 0.01, 0},
                                            {-0.1, -0.1, 0}, {19.9, -19.9, 0}, {20.1, 0, 0}};
  const std::vector<double> values{10, 20, 30, 7, 5, 99};
  const IntensityGrid S = build_intensity_grid(points, values, Pose2d{}, g);
  ASSERT_EQ(S.cells.size(), 40000u);
  // The vehicle is at the corner of the four central cells.
  EXPECT_EQ(S.at(100, 100).count, 3u);
  EXPECT_NEAR(S.at(100, 100).mean, 20.0, 1e-5);
  EXPECT_NEAR(S.at(100, 100).variance(), 200.0 / 3.0, 1e-4);  // population variance of 10, 20, 30
  EXPECT_EQ(S.at(99, 99).count, 1u);
  EXPECT_EQ(S.at(199, 0).count, 1u);
  EXPECT_NEAR(S.cell_centre(100, 100).x(), 0.1, 1e-12);
  uint32_t total = 0;
  for (const IntensityCell& c : S.cells) total += c.count;
  EXPECT_EQ(total, 5u);  // the point 20.1 m ahead is off the grid
  EXPECT_THROW(S.at(200, 0), std::out_of_range);
  EXPECT_THROW(build_intensity_grid(points, {1.0}, Pose2d{}, g), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------
// Matching (Eq. 14-18)

TEST_F(Aps, RecoversAKnownOffsetOnACrosswalkWithTheVehicleTurned) {
  IntensityMap map(*crosswalk_dir_);
  const IntensityGridParams g;
  const Scan scan = scan_at(crosswalk, kTruth, g, 3);
  const Pose2d prior = prior_from(kTruth, kPriorError);
  const IntensityGrid S = build_intensity_grid(scan.points, scan.intensities, prior, g);
  const ApsParams params;

  const auto start = std::chrono::steady_clock::now();
  const ApsResult r = aps_match(S, map, params);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  ASSERT_TRUE(r.ok);
  const Eigen::Vector2d err = vehicle_error(r, kTruth);
  EXPECT_LT(std::fabs(err.x()), kResolution) << "longitudinal error";
  EXPECT_LT(std::fabs(err.y()), kResolution) << "lateral error";
  EXPECT_NEAR(r.offset_vehicle.x(), kPriorError.x(), kResolution);
  EXPECT_NEAR(r.offset_vehicle.y(), kPriorError.y(), kResolution);
  const Eigen::Matrix2d cv = vehicle_covariance(r, kTruth.yaw);
  std::printf("[ aps ] crosswalk: offset (%.3f, %.3f) m, truth (%.1f, %.1f); std (%.3f, %.3f) m; %d cells; %.1f ms\n",
              r.offset_vehicle.x(), r.offset_vehicle.y(), kPriorError.x(), kPriorError.y(), std::sqrt(cv(0, 0)),
              std::sqrt(cv(1, 1)), r.cells_used, ms);
  // The map is read: the estimate is not just the prior.
  EXPECT_GT((r.position - Eigen::Vector2d(prior.x, prior.y)).norm(), 1.0);
}

// A line along the road only ahead of the car, 5 to 20 m out: turning S by e about the car moves the
// line's cells sideways by e times their distance, so the match slides across by about e times the
// line's mean distance (12.5 m) and not along: yaw_coupling ~ (0, -12.5) m/rad, and the position APS
// finds at a prior heading e off moves by it.
bool line_ahead(const Eigen::Vector2d& p) { return p.x() >= 25 && p.x() < 40 && p.y() >= 0.2 && p.y() < 0.6; }

TEST(ApsYawCoupling, ALineAheadSlidesSidewaysWithTheHeadingError) {
  const std::string dir = build_map(line_ahead, "line_ahead", 5);
  IntensityMap map(dir);
  const Pose2d truth{20.0, 0.0, 0.0};
  const IntensityGridParams g;
  const Scan scan = scan_at(line_ahead, truth, g, 6);
  const ApsResult at_truth = aps_match(build_intensity_grid(scan.points, scan.intensities, truth, g), map);
  ASSERT_TRUE(at_truth.ok);
  EXPECT_NEAR(at_truth.yaw_coupling.y(), -12.5, 2.5);
  EXPECT_LT(std::fabs(at_truth.yaw_coupling.x()), 2.0);
  // A prior heading 1 deg off: the lateral answer moves by J * e (-0.22 m), within a step.
  const double e = std::numbers::pi / 180.0;
  const ApsResult turned =
      aps_match(build_intensity_grid(scan.points, scan.intensities, {truth.x, truth.y, truth.yaw + e}, g), map);
  ASSERT_TRUE(turned.ok);
  EXPECT_NEAR(turned.position.y() - at_truth.position.y(), at_truth.yaw_coupling.y() * e, kResolution);
  fs::remove_all(dir);
}

TEST_F(Aps, AnErrorBeyondTheSearchWindowIsNotRecovered) {
  IntensityMap map(*crosswalk_dir_);
  const IntensityGridParams g;
  const ApsParams params;
  const Eigen::Vector2d too_far(params.longitudinal_range_m + 1.5, 0.0);
  const Scan scan = scan_at(crosswalk, kTruth, g, 4);
  const IntensityGrid S = build_intensity_grid(scan.points, scan.intensities, prior_from(kTruth, too_far), g);
  const ApsResult r = aps_match(S, map, params);
  ASSERT_TRUE(r.ok);
  // The centre of mass of a distribution over the window cannot leave it...
  EXPECT_LE(std::fabs(r.offset_vehicle.x()), params.longitudinal_range_m + 1e-9);
  EXPECT_LE(std::fabs(r.offset_vehicle.y()), params.lateral_range_m + 1e-9);
  // ...so at least the excess remains as error.
  const Eigen::Vector2d err = vehicle_error(r, kTruth);
  std::printf("[ aps ] beyond window: offset (%.3f, %.3f) m for an error of (%.1f, %.1f)\n", r.offset_vehicle.x(),
              r.offset_vehicle.y(), too_far.x(), too_far.y());
  EXPECT_GT(err.norm(), too_far.x() - params.longitudinal_range_m - 1e-9);
}

TEST_F(Aps, AFeaturelessRoadGivesABroadDistribution) {
  const IntensityGridParams g;
  const ApsParams params;
  const Pose2d prior = prior_from(kTruth, kPriorError);

  IntensityMap flat(*asphalt_dir_);
  const Scan flat_scan = scan_at(plain_asphalt, kTruth, g, 5);
  const ApsResult r_flat =
      aps_match(build_intensity_grid(flat_scan.points, flat_scan.intensities, prior, g), flat, params);

  IntensityMap marked(*crosswalk_dir_);
  const Scan marked_scan = scan_at(crosswalk, kTruth, g, 5);
  const ApsResult r_marked =
      aps_match(build_intensity_grid(marked_scan.points, marked_scan.intensities, prior, g), marked, params);

  ASSERT_TRUE(r_flat.ok);
  ASSERT_TRUE(r_marked.ok);
  const Eigen::Matrix2d c_flat = vehicle_covariance(r_flat, kTruth.yaw);
  const Eigen::Matrix2d c_marked = vehicle_covariance(r_marked, kTruth.yaw);
  std::printf("[ aps ] std (long, lat): flat (%.3f, %.3f) m, crosswalk (%.3f, %.3f) m\n", std::sqrt(c_flat(0, 0)),
              std::sqrt(c_flat(1, 1)), std::sqrt(c_marked(0, 0)), std::sqrt(c_marked(1, 1)));
  EXPECT_GT(std::sqrt(c_flat(0, 0)), 0.5);
  EXPECT_GT(c_flat.trace(), 10 * c_marked.trace());
  // Against a uniform spread over the window: plain asphalt says nothing on either axis, the crosswalk
  // pins both (the localizer updates only the axes at most aps_max_spread_ratio wide).
  std::printf("[ aps ] spread ratio (long, lat): flat (%.2f, %.2f), crosswalk (%.3f, %.3f)\n", r_flat.spread_ratio.x(),
              r_flat.spread_ratio.y(), r_marked.spread_ratio.x(), r_marked.spread_ratio.y());
  EXPECT_GT(r_flat.spread_ratio.minCoeff(), LocalizerParams{}.aps_max_spread_ratio);
  EXPECT_LT(r_marked.spread_ratio.maxCoeff(), 0.05);
}

TEST_F(Aps, TooFewUsableCellsGiveNoEstimate) {
  IntensityMap map(*crosswalk_dir_);
  const IntensityGridParams g;
  const ApsParams params;
  const Pose2d prior = prior_from(kTruth, kPriorError);
  // Points in a 1 m x 1 m patch: 25 cells, fewer than min_cells.
  std::vector<Eigen::Vector3d> points;
  std::vector<double> values;
  for (double x = 0.01; x < 1.0; x += 0.05)
    for (double y = 0.01; y < 1.0; y += 0.05) {
      points.emplace_back(x, y, 0.0);
      values.push_back(kAsphalt);
    }
  const ApsResult r = aps_match(build_intensity_grid(points, values, prior, g), map, params);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.cells_used, 25);
  EXPECT_EQ(r.position, Eigen::Vector2d(prior.x, prior.y));

  // Cells with no more than n_e points do not count either: one point in every cell of S.
  std::vector<Eigen::Vector3d> one_each;
  const IntensityGrid empty = build_intensity_grid({}, {}, prior, g);
  for (int row = 0; row < g.height_cells; ++row)
    for (int col = 0; col < g.width_cells; ++col) {
      const Eigen::Vector2d c = empty.cell_centre(col, row);
      one_each.emplace_back(c.x(), c.y(), 0.0);
    }
  const ApsResult sparse =
      aps_match(build_intensity_grid(one_each, std::vector<double>(one_each.size(), kAsphalt), prior, g), map, params);
  EXPECT_FALSE(sparse.ok);
  EXPECT_EQ(sparse.cells_used, 0);
}

// ---------------------------------------------------------------------------------------------------
// The steps of aps_match on their own

TEST(ApsSteps, TheSearchWindowHasWholeStepsOfWholeCells) {
  const ApsSearchWindow paper = aps_search_window(ApsParams{}, kResolution);  // +-3 m, +-1 m in 0.2 m steps
  EXPECT_EQ(paper.nx, 15);
  EXPECT_EQ(paper.ny, 5);
  EXPECT_EQ(paper.step_cells, 1);
  EXPECT_EQ(paper.offsets_x(), 31);
  EXPECT_EQ(paper.offsets_y(), 11);
  EXPECT_NEAR(paper.offset(0, 0).x(), -3.0, 1e-12);
  EXPECT_NEAR(paper.offset(30, 10).y(), 1.0, 1e-12);

  ApsParams coarse;
  coarse.step_m = 0.4;                // two cells
  coarse.longitudinal_range_m = 1.0;  // 2.5 steps: the half step is not searched
  const ApsSearchWindow w = aps_search_window(coarse, kResolution);
  EXPECT_EQ(w.step_cells, 2);
  EXPECT_EQ(w.nx, 2);
  EXPECT_EQ(w.margin_x(), 4);

  ApsParams bad = coarse;
  bad.step_m = 0.3;  // a cell and a half
  EXPECT_THROW(aps_search_window(bad, kResolution), std::invalid_argument);
  bad = coarse;
  bad.lateral_range_m = -1;
  EXPECT_THROW(aps_search_window(bad, kResolution), std::invalid_argument);
}

TEST(ApsSteps, LogProbabilitiesAreEq14sExponent) {
  const std::vector<double> log_p = aps_log_probabilities({0.0f, 2.0f, 4.0f}, 0.5);
  ASSERT_EQ(log_p.size(), 3u);
  EXPECT_DOUBLE_EQ(log_p[0], 0.0);
  EXPECT_DOUBLE_EQ(log_p[1], -0.5);
  EXPECT_DOUBLE_EQ(log_p[2], -1.0);
}

// A 5 x 3 window of 0.2 m steps: offsets -0.4..0.4 m along x, -0.2..0.2 m along y.
ApsSearchWindow small_window() {
  ApsParams p;
  p.longitudinal_range_m = 0.4;
  p.lateral_range_m = 0.2;
  return aps_search_window(p, kResolution);
}

TEST(ApsSteps, OneCertainOffsetIsTheEstimateToWithinAStep) {
  const ApsSearchWindow w = small_window();
  std::vector<double> log_p(size_t(w.offsets_x() * w.offsets_y()), -1e4);  // exp() of these is 0
  log_p[size_t(1 * w.offsets_x() + 3)] = 0;                                // offset (0.2, 0) m
  const OffsetMoments m = aps_offset_moments(log_p, w);
  EXPECT_NEAR(m.mean.x(), 0.2, 1e-12);
  EXPECT_NEAR(m.mean.y(), 0.0, 1e-12);
  const double quantisation = 0.2 * 0.2 / 12;  // a uniform spread over one step
  EXPECT_NEAR(m.covariance(0, 0), quantisation, 1e-12);
  EXPECT_NEAR(m.covariance(1, 1), quantisation, 1e-12);
  EXPECT_NEAR(m.covariance(0, 1), 0.0, 1e-12);
  EXPECT_FALSE(aps_peak_on_edge(log_p, w));
}

TEST(ApsSteps, AFlatDistributionIsCentredAndAsWideAsTheWindow) {
  const ApsSearchWindow w = small_window();
  const std::vector<double> log_p(size_t(w.offsets_x() * w.offsets_y()), -7.0);
  const OffsetMoments m = aps_offset_moments(log_p, w);
  EXPECT_NEAR(m.mean.norm(), 0.0, 1e-12);
  // Variance of k * step over k in -n..n, uniform: step^2 n (n + 1) / 3; plus the step's quantisation.
  const double step2 = 0.2 * 0.2;
  EXPECT_NEAR(m.covariance(0, 0), step2 * 2 * 3 / 3 + step2 / 12, 1e-12);
  EXPECT_NEAR(m.covariance(1, 1), step2 * 1 * 2 / 3 + step2 / 12, 1e-12);
  EXPECT_NEAR(m.covariance(0, 1), 0.0, 1e-12);
}

TEST(ApsSteps, APeakOnTheBorderIsOnTheEdgeOnlyAlongAnAxisThatIsSearched) {
  const ApsSearchWindow w = small_window();
  const size_t n = size_t(w.offsets_x() * w.offsets_y());
  auto peak_at = [&](int i, int j) {
    std::vector<double> log_p(n, -1.0);
    log_p[size_t(j * w.offsets_x() + i)] = 0;
    return log_p;
  };
  EXPECT_FALSE(aps_peak_on_edge(peak_at(2, 1), w));
  EXPECT_TRUE(aps_peak_on_edge(peak_at(0, 1), w));
  EXPECT_TRUE(aps_peak_on_edge(peak_at(4, 1), w));
  EXPECT_TRUE(aps_peak_on_edge(peak_at(2, 0), w));
  EXPECT_TRUE(aps_peak_on_edge(peak_at(2, 2), w));

  ApsParams along_only;
  along_only.longitudinal_range_m = 0.4;
  along_only.lateral_range_m = 0;  // one row of offsets: its border is its middle
  const ApsSearchWindow row = aps_search_window(along_only, kResolution);
  std::vector<double> log_p(size_t(row.offsets_x()), -1.0);
  log_p[2] = 0;
  EXPECT_FALSE(aps_peak_on_edge(log_p, row));
}

// Along a +-3 m x +-0.2 m window: the best offset at 0 and another peak 2 m ahead (on another lateral
// row), 7 below it; the flanks of the best within 1.5 m do not count.
TEST(ApsSteps, TheAlongMarginIsTheGapToTheBestOtherPeakAlongTheRoad) {
  ApsParams p;
  p.longitudinal_range_m = 3.0;
  p.lateral_range_m = 0.2;
  const ApsSearchWindow w = aps_search_window(p, kResolution);
  const size_t n = size_t(w.offsets_x() * w.offsets_y());
  auto at = [&](int i, int j) { return size_t(j * w.offsets_x() + i); };
  auto profile = [&](auto height) {  // height(x) along the road, the same on the middle row; lower on the others
    std::vector<double> log_p(n);
    for (int j = 0; j < w.offsets_y(); ++j)
      for (int i = 0; i < w.offsets_x(); ++i) log_p[at(i, j)] = height(w.offset(i, j).x()) - (j == 1 ? 0.0 : 50.0);
    return log_p;
  };
  const auto one_peak = profile([](double x) { return -20 * x * x; });
  EXPECT_TRUE(std::isinf(aps_along_margin(one_peak, w, p.distinct_separation_m)));

  auto two_peaks = one_peak;
  const int ahead = w.nx + 10;   // +2 m
  two_peaks[at(ahead, 0)] = -7;  // above its neighbours on every row
  EXPECT_NEAR(aps_along_margin(two_peaks, w, p.distinct_separation_m), 7.0, 1e-12);
  // Closer than the separation, it is part of the best peak.
  EXPECT_TRUE(std::isinf(aps_along_margin(two_peaks, w, 2.5)));

  // Rising towards the window's border: a peak beyond it may be higher still, so the border counts.
  const auto rising = profile([](double x) { return x < 2.5 ? -20 * x * x : -40 + 10 * (x - 2.5); });
  EXPECT_NEAR(aps_along_margin(rising, w, p.distinct_separation_m), 40 - 5, 1e-9);
}

// A centre line dashed every 3 m (1.5 m paint, 1.5 m gap) the whole length of the road, and the same
// with one stop line across it: seen by a scan, the dashes fit as well a period ahead or behind, so
// APS's best offset along the road beats the next peak only by noise; the stop line is one of a kind.
bool dashed_centre_line(const Eigen::Vector2d& p) { return std::fabs(p.y()) < 0.075 && std::fmod(p.x(), 3.0) < 1.5; }
bool dashes_and_a_stop_line(const Eigen::Vector2d& p) {
  return dashed_centre_line(p) || (p.x() >= 31.0 && p.x() < 31.5 && p.y() > -3.5 && p.y() < 0);
}

TEST(ApsAlongMargin, DashesRepeatingAlongTheRoadLeaveNoMarginAStopLineDoes) {
  const LocalizerParams defaults;
  const IntensityGridParams g;
  ApsParams params;  // a window grown to a cold start's doubt: +-6 m along the road
  params.longitudinal_range_m = 6.0;
  const Eigen::Vector2d error(1.0, 0.0);
  const Pose2d truth{30.0, 0.0, 0.0};
  double margins[2] = {0, 0};
  int k = 0;
  for (Pattern pattern : {dashed_centre_line, dashes_and_a_stop_line}) {
    const std::string dir = build_map(pattern, "margin_" + std::to_string(k), 7);
    IntensityMap map(dir);
    const Scan scan = scan_at(pattern, truth, g, 8);
    const ApsResult r =
        aps_match(build_intensity_grid(scan.points, scan.intensities, prior_from(truth, error), g), map, params);
    ASSERT_TRUE(r.ok);
    margins[k++] = r.along_margin;
    fs::remove_all(dir);
  }
  std::printf("[ aps ] along margin: dashes %.1f, dashes and a stop line %.1f (Eq. 14 log P)\n", margins[0],
              margins[1]);
  EXPECT_LT(margins[0], defaults.aps_min_along_margin);
  EXPECT_GT(margins[1], defaults.relocalization.min_aps_margin);
}

TEST_F(Aps, GridCellsMustBeTheMapsCells) {
  IntensityMap map(*crosswalk_dir_);
  IntensityGridParams g;
  g.cell_m = 0.25;
  const IntensityGrid S = build_intensity_grid({}, {}, kTruth, g);
  EXPECT_THROW(aps_match(S, map, ApsParams{}), std::invalid_argument);
  ApsParams half_step;
  half_step.step_m = 0.1;  // not a whole number of cells
  EXPECT_THROW(aps_match(build_intensity_grid({}, {}, kTruth, IntensityGridParams{}), map, half_step),
               std::invalid_argument);
}

}  // namespace
}  // namespace lidarloop
