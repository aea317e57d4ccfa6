// Curb matching over a grid of hypotheses (curb_hypotheses.hpp): on a straight road with two curbs a
// 2.5 m lateral error is recovered and the longitudinal reported ambiguous; at a junction the
// longitudinal error is recovered too; too few curbs give no answer.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "localizer/curb_hypotheses.hpp"

namespace lidarloop {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kSpacing = 0.1;        // m between map curb points (CurbLayer's default)
constexpr double kHalfWidth = 5.0;      // m from the centre line to each curb
constexpr double kMapHalf = 40.0;       // m of road either side of the origin
constexpr double kSensorRange = 20.0;   // m: the curbs a scan's accumulated features reach
constexpr double kFeatureNoise = 0.05;  // m, the detector's
constexpr int kFeatureStride = 4;       // every 4th curb point is a feature: ~100 a scan, as on the campus drive

// Curbs either side of a road along x; with a junction, a side road leaving it to the left (+y) at
// x = 0 (the left curb broken where it joins): a T, which no shift or small turn maps onto itself.
// One curb after the other, so that every kFeatureStride-th point samples each of them.
std::vector<Eigen::Vector2d> road(bool junction) {
  std::vector<Eigen::Vector2d> m;
  for (double t = -kMapHalf; t <= kMapHalf; t += kSpacing) m.emplace_back(t, -kHalfWidth);
  for (double t = -kMapHalf; t <= kMapHalf; t += kSpacing)
    if (!junction || std::fabs(t) >= kHalfWidth) m.emplace_back(t, kHalfWidth);
  if (junction)
    for (double side : {-kHalfWidth, kHalfWidth})
      for (double t = kHalfWidth; t <= kMapHalf; t += kSpacing) m.emplace_back(side, t);
  return m;
}

// The map's curbs within sensor range of `truth`, as the car would detect them, placed at `prior`.
std::vector<Eigen::Vector2d> features_at(const std::vector<Eigen::Vector2d>& map, const Pose2d& truth,
                                         const Pose2d& prior, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kFeatureNoise);
  std::vector<Eigen::Vector2d> f;
  const Pose2d to_vehicle = truth.inverse();
  for (size_t i = 0; i < map.size(); i += kFeatureStride) {
    const Eigen::Vector2d v = to_vehicle.apply(map[i]);
    if (v.norm() > kSensorRange) continue;
    f.push_back(prior.apply(v + Eigen::Vector2d(noise(rng), noise(rng))));
  }
  return f;
}

struct Case {
  CurbHypothesesResult result;
  Pose2d truth;
};

// The car at `truth`, its prior `error` away (the prior's vehicle frame: truth = prior * error).
Case search(bool junction, const Pose2d& error) {
  const std::vector<Eigen::Vector2d> curbs = road(junction);
  const MapIndex index(curbs);
  const Pose2d truth{1.0, -0.8, 0.0};  // heading along the road
  const Pose2d prior = truth.compose(error.inverse());
  const auto features = features_at(curbs, truth, prior, 1);
  const auto start = std::chrono::steady_clock::now();
  const CurbHypothesesResult r = curb_hypotheses(features, index, prior);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "[ curbs ] %s: best (%.3f, %.3f, %.2f deg) truth (%.3f, %.3f, %.2f deg) score %.3f inliers %.2f; "
      "%zu places, margin %.3f, spread (%.2f m, %.2f m, %.2f deg); %zu features, %d ICP runs, %.1f ms\n",
      junction ? "junction" : "straight", r.best.pose.x, r.best.pose.y, r.best.pose.yaw / kDeg, truth.x, truth.y,
      truth.yaw / kDeg, r.best.score, r.best.inlier_ratio, r.places.size(), r.score_margin, r.spread.x(), r.spread.y(),
      r.spread.z() / kDeg, features.size(), r.icp_runs, ms);
  return {r, truth};
}

// Error in the truth's vehicle frame (longitudinal, lateral, yaw).
Pose2d error_of(const Case& c) { return relative(c.truth, c.result.best.pose); }

TEST(CurbHypotheses, StraightRoadRecoversTheLateralAndSaysTheLongitudinalIsFree) {
  const Case c = search(false, Pose2d{1.0, 2.5, 2.0 * kDeg});
  ASSERT_TRUE(c.result.ok);
  const Pose2d e = error_of(c);
  EXPECT_LT(std::fabs(e.y), 0.1) << "lateral";
  EXPECT_LT(std::fabs(e.yaw), 0.5 * kDeg) << "yaw";
  EXPECT_TRUE(c.result.ambiguous_longitudinal);
  EXPECT_FALSE(c.result.ambiguous_lateral);
  EXPECT_FALSE(c.result.ambiguous_yaw);
  EXPECT_GT(c.result.best.inlier_ratio, 0.9);
}

TEST(CurbHypotheses, JunctionRecoversTheLongitudinalToo) {
  const Case c = search(true, Pose2d{3.0, 2.5, 2.0 * kDeg});
  ASSERT_TRUE(c.result.ok);
  const Pose2d e = error_of(c);
  EXPECT_LT(std::hypot(e.x, e.y), 0.1);
  EXPECT_LT(std::fabs(e.yaw), 0.5 * kDeg);
  EXPECT_FALSE(c.result.ambiguous_longitudinal);
  EXPECT_FALSE(c.result.ambiguous_lateral);
  EXPECT_FALSE(c.result.ambiguous_yaw);
  EXPECT_GT(c.result.score_margin, 0.1);
  EXPECT_GT(c.result.best.inlier_ratio, 0.9);
}

TEST(CurbHypotheses, SpreadOverStepsGivesTheOneShotAnswer) {
  const std::vector<Eigen::Vector2d> curbs = road(true);
  const MapIndex index(curbs);
  const Pose2d truth{1.0, -0.8, 0.0}, prior = truth.compose(Pose2d{3.0, 2.5, 2.0 * kDeg}.inverse());
  const auto features = features_at(curbs, truth, prior, 2);
  const CurbHypothesesResult once = curb_hypotheses(features, index, prior);
  CurbHypothesesParams p;
  p.max_icp_runs_per_step = 10;
  CurbHypothesisSearch search(p);
  int steps = 0;
  while (!search.done() && steps < 100) {
    EXPECT_FALSE(search.result().ok);
    search.step(features, index, prior);
    ++steps;
  }
  ASSERT_TRUE(search.done());
  EXPECT_EQ(steps, (once.icp_runs + 9) / 10);
  const CurbHypothesesResult& r = search.result();
  ASSERT_TRUE(r.ok);
  EXPECT_DOUBLE_EQ(r.best.pose.x, once.best.pose.x);
  EXPECT_DOUBLE_EQ(r.best.pose.y, once.best.pose.y);
  EXPECT_DOUBLE_EQ(r.best.score, once.best.score);
  EXPECT_EQ(r.places.size(), once.places.size());
  search.restart();
  EXPECT_FALSE(search.done());
}

// The car drives on between steps and the prior follows it with odometry: the corrections ICP found on
// earlier steps still put the car where it is at the last one.
TEST(CurbHypotheses, SpreadOverStepsFollowsAMovingPrior) {
  const std::vector<Eigen::Vector2d> curbs = road(true);
  const MapIndex index(curbs);
  const Pose2d motion{0.5, 0.0, 0.5 * kDeg};  // one scan's odometry
  Pose2d truth{-1.0, -0.8, 0.0};
  Pose2d prior = truth.compose(Pose2d{3.0, 2.5, 2.0 * kDeg}.inverse());
  CurbHypothesesParams p;
  p.max_icp_runs_per_step = 40;
  CurbHypothesisSearch search(p);
  int steps = 0;
  while (!search.done() && steps < 20) {
    search.step(features_at(curbs, truth, prior, uint32_t(steps)), index, prior);
    truth = truth.compose(motion);
    prior = prior.compose(motion);
    ++steps;
  }
  ASSERT_TRUE(search.done());
  const CurbHypothesesResult& r = search.result();
  ASSERT_TRUE(r.ok);
  const Pose2d last_truth = truth.compose(motion.inverse());  // the result is at the last step's prior
  const Pose2d e = relative(last_truth, r.best.pose);
  EXPECT_LT(std::hypot(e.x, e.y), 0.1) << steps << " steps";
  EXPECT_LT(std::fabs(e.yaw), 0.5 * kDeg);
  EXPECT_FALSE(r.ambiguous_longitudinal);
}

TEST(CurbHypotheses, TooFewCurbsOrBadParametersGiveNoAnswer) {
  const MapIndex index(road(false));
  const std::vector<Eigen::Vector2d> few{{0, 5}, {1, 5}};
  EXPECT_FALSE(curb_hypotheses(few, index, Pose2d{}).ok);
  CurbHypothesesParams p;
  p.lateral_step_m = 0;
  EXPECT_THROW(curb_hypotheses(few, index, Pose2d{}, p), std::invalid_argument);
}

}  // namespace
}  // namespace lidarloop
