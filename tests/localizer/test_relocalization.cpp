// The relocalization's search (relocalization.hpp) while the car drives on: its hypotheses are where the
// car was when they were taken, and a search takes several scans, so they must move with the car by
// odometry. At a T junction, whose curbs place the car on every axis, a car 1.5 m and 2 deg off its
// prior is found where it is, metres after the hypothesis that allows it was taken.
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "localizer/intensity_map.hpp"
#include "localizer/relocalization.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kHalfWidth = 5.0;     // m from the main road's centre line to each curb
constexpr double kSpacing = 0.25;      // m between map curb points
constexpr double kSensorRange = 20.0;  // m: the curbs a scan's features reach
constexpr double kFeatureNoise = 0.03;
constexpr double kStepM = 1.0;  // m driven between two scans (10 m/s at 10 Hz)

// A main road along x (curbs at y = +-5) with a side road leaving it to the left between x = -5 and 5.
std::vector<Eigen::Vector2d> t_junction() {
  std::vector<Eigen::Vector2d> m;
  for (double x = -60; x <= 60; x += kSpacing) {
    m.emplace_back(x, -kHalfWidth);
    if (std::fabs(x) >= kHalfWidth) m.emplace_back(x, kHalfWidth);
  }
  for (double y = kHalfWidth; y <= 40; y += kSpacing) {
    m.emplace_back(-kHalfWidth, y);
    m.emplace_back(kHalfWidth, y);
  }
  return m;
}

// The map's curbs seen from `truth`, placed at `prior` (world frame, as the localizer hands them over).
std::vector<Eigen::Vector2d> features(const std::vector<Eigen::Vector2d>& map, const Pose2d& truth, const Pose2d& prior,
                                      std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, kFeatureNoise);
  std::vector<Eigen::Vector2d> f;
  const Pose2d to_vehicle = truth.inverse();
  for (const Eigen::Vector2d& p : map) {
    const Eigen::Vector2d v = to_vehicle.apply(p);
    if (v.norm() <= kSensorRange) f.push_back(prior.apply(v + Eigen::Vector2d(noise(rng), noise(rng))));
  }
  return f;
}

// A map without paint: the search here is the curbs' alone.
std::string empty_intensity_map() {
  IntensityMapHeader h;
  h.world = "relocalization_test";
  h.world_hash = "0123456789abcdef";
  h.origin = {31.2856, 121.2147, 4.0};
  const fs::path dir = fs::path(::testing::TempDir()) / ("lidarloop_reloc_" + std::to_string(::getpid()));
  IntensityMapBuilder(h).save(dir.string());
  return dir.string();
}

// Drives from x = -25 along the main road; the filter's prior is `error` off the truth (in the truth's
// vehicle frame); the hypothesis is the truth at the search's start, as sure as a tracking filter
// (0.2 m, 0.3 deg). Odometry (exact here) carries it with the car when `odometry_moves`; the first
// relocation found, if any, and the truth then.
struct Outcome {
  std::optional<Relocation> found;
  Pose2d truth;
};
Outcome drive(const Pose2d& error, bool odometry_moves) {
  const std::vector<Eigen::Vector2d> map = t_junction();
  const MapIndex index(map);
  IntensityMap intensity(empty_intensity_map());
  Relocalizer search;
  Pose2d truth{-25, 0, 0};
  const Pose2d start_odometry{0, 0, 0};
  search.start(Eigen::Vector3d(6, 6, 4 * kDeg), {{truth, Eigen::Vector3d(0.2, 0.2, 0.3 * kDeg)}}, start_odometry);
  std::mt19937 rng(7);
  for (int scan = 1; scan <= 20; ++scan) {
    truth = truth.compose(Pose2d{kStepM, 0, 0});
    const Pose2d odometry = odometry_moves ? Pose2d{scan * kStepM, 0, 0} : start_odometry;
    const Pose2d prior = truth.compose(error);
    const std::optional<Relocation> found =
        search.step(nullptr, intensity, features(map, truth, prior, rng), index, prior, odometry);
    if (found && found->longitudinal) return {found, truth};
  }
  return {std::nullopt, truth};
}

TEST(Relocalizer, HypothesesMoveWithTheCarSoTheSearchFindsItMetresOn) {
  const Pose2d error{0.0, 1.5, 2.0 * kDeg};
  const Outcome o = drive(error, true);
  ASSERT_TRUE(o.found) << "no relocation in 20 scans";
  const Pose2d off = relative(o.truth, o.found->pose);
  EXPECT_LT(std::hypot(off.x, off.y), 0.3);
  EXPECT_LT(std::fabs(off.yaw), 0.5 * kDeg);
  // The car drove on while the search ran: the place was found well after the hypothesis was taken.
  EXPECT_GT(o.truth.x - (-25.0), 3 * kStepM);
}

// The same drive with the hypothesis left where it was taken: the car is soon beyond its 99.9 % region,
// and every place found there is refused.
TEST(Relocalizer, AHypothesisLeftBehindRefusesTheTruth) {
  const Outcome o = drive(Pose2d{0.0, 1.5, 2.0 * kDeg}, false);
  EXPECT_FALSE(o.found);
}

}  // namespace
}  // namespace lidarloop
