// The pieces of "lost and found": the GPS step detector, the lost detector, the protection bounds and
// the innovation scale, each against a known truth.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "localizer/gps_step_detector.hpp"
#include "localizer/innovation_scale.hpp"
#include "localizer/lost_detector.hpp"
#include "localizer/protection_bound.hpp"

namespace lidarloop {
namespace {

constexpr int64_t kFixNs = 100'000'000;  // 10 Hz

// A low-cost receiver's innovations: a slow bias (2 m, tau 120 s, as the simulator's) plus 0.4 m white.
struct Receiver {
  std::mt19937_64 rng{7};
  std::normal_distribution<double> n{0, 1};
  Eigen::Vector2d bias{1.5, -1.2};
  Eigen::Vector2d next() {
    const double a = std::exp(-0.1 / 120.0);
    bias = a * bias + 2.0 * std::sqrt(1 - a * a) * Eigen::Vector2d(n(rng), n(rng));
    return bias + 0.4 * Eigen::Vector2d(n(rng), n(rng));
  }
};

TEST(GpsStepDetector, TheWanderingBiasIsNoStepAndAFourMetreJumpIs) {
  GpsStepDetector d;
  Receiver r;
  int false_steps = 0;
  for (int k = 0; k < 3000; ++k) false_steps += d.step(k * kFixNs, r.next());  // 5 minutes
  EXPECT_EQ(false_steps, 0);
  // A 4 m jump: every fix of it is a step, and the level stays where it was before.
  const Eigen::Vector2d level = *d.level();
  for (int k = 3000; k < 3010; ++k) EXPECT_TRUE(d.step(k * kFixNs, r.next() + Eigen::Vector2d(2.4, 3.2)));
  EXPECT_LT((*d.level() - level).norm(), 1e-12);
  // Restarted, the jumped level is learnt and the fixes are no longer steps.
  d.restart();
  int steps_after = 0;
  for (int k = 3010; k < 3100; ++k) steps_after += d.step(k * kFixNs, r.next() + Eigen::Vector2d(2.4, 3.2));
  EXPECT_EQ(steps_after, 0);
}

TEST(GpsStepDetector, AFilterCorrectionShiftedIntoTheLevelIsNoStep) {
  GpsStepDetector d;
  Receiver r;
  for (int k = 0; k < 100; ++k) d.step(k * kFixNs, r.next());
  d.shift({-3.0, 0.0});  // the map moved the filter 3 m ahead: innovations are 3 m less
  EXPECT_FALSE(d.step(100 * kFixNs, r.next() + Eigen::Vector2d(-3.0, 0.0)));
}

TEST(LostDetector, RaisedByEnoughDisagreementsInTheWindowClearedByAgreementOnBothAxes) {
  LostDetector d;  // 4 in 0.5 s; 3 agreements per axis
  for (int k = 0; k < 3; ++k) d.disagree({k * kFixNs, {1, 0}});
  EXPECT_FALSE(d.lost());
  d.disagree({3 * kFixNs, {1, 0}});
  EXPECT_TRUE(d.lost());
  EXPECT_TRUE(d.searching());
  d.found();
  EXPECT_FALSE(d.searching());
  for (int k = 0; k < 3; ++k) d.agree(false, true, 0.05, {0, 0});  // across only: a straight road's curbs
  EXPECT_TRUE(d.lost());
  for (int k = 0; k < 3; ++k) d.agree(true, false, 0.05, {0, 0});
  EXPECT_FALSE(d.lost());
}

TEST(LostDetector, AColdStartStillPulledAlongTheRoadIsNotConverged) {
  // intersections seed 2: APS pulled a cold start 0.3 m back every scan, from 3 m off, while the
  // filter's sigma was already under the converged one. Those matches confirm nothing.
  LostDetector d;
  const LostParams p;
  d.start_search();
  const double sigma = 0.9 * p.converged_sigma_m, pull = 1.5 * p.converged_sigma_m;
  for (int k = 0; k < 10; ++k) {
    d.agree(true, false, sigma, {pull, 0.0});  // APS along, still moving the filter
    d.agree(false, true, sigma, {0.0, 0.01});  // curbs across
  }
  EXPECT_TRUE(d.lost());
  // Once the matches find the filter where they are, it has converged.
  for (int k = 0; k < p.confirmations; ++k) {
    d.agree(true, false, sigma, {0.5 * p.converged_sigma_m, 0.0});
    d.agree(false, true, sigma, {0.0, 0.01});
  }
  EXPECT_FALSE(d.lost());
}

TEST(LostDetector, DisagreementsSpreadOverTimeDoNotRaiseIt) {
  LostDetector d;
  for (int k = 0; k < 20; ++k) d.disagree({k * 2 * kFixNs * 2, {1, 0}});  // one every 0.4 s
  EXPECT_FALSE(d.lost());
}

TEST(ProtectionBound, IsTheNormalQuantileTimesSigmaOnTheCarsAxesPlusARefusedOffset) {
  EXPECT_NEAR(normal_two_sided_quantile(0.9973), 3.0, 2e-3);
  EXPECT_NEAR(normal_two_sided_quantile(0.9999), 3.8906, 1e-3);
  // A car heading north (yaw 90 deg): x of the map is across it.
  Eigen::Matrix3d P = Eigen::Vector3d(0.04, 0.01, 1e-6).asDiagonal();
  const Pose2d north{0, 0, M_PI / 2};
  const IntegrityParams integrity;
  const double k = normal_two_sided_quantile(integrity.probability);
  ProtectionBounds b = protection_bounds(P, north, {}, integrity);
  EXPECT_NEAR(b.lateral_m, k * 0.2, 1e-9);
  EXPECT_NEAR(b.longitudinal_m, k * 0.1, 1e-9);
  // A refused observation 2 m ahead of the car widens the longitudinal bound by 2 m.
  b = protection_bounds(P, north, {{0, {0, 2.0}}}, integrity);
  EXPECT_NEAR(b.longitudinal_m, k * 0.1 + 2.0, 1e-9);
  EXPECT_NEAR(b.lateral_m, k * 0.2, 1e-9);
}

TEST(InnovationScale, LearnsHowManyTimesTooNarrowAMatcherIs) {
  // A matcher that claims 0.1 m but errs by 0.3 m along the car (9 times the variance) and as claimed
  // across it, seen by a filter whose own variance is 0.05^2.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1);
  InnovationScale s({200, 25.0});
  const Eigen::Vector2d prior(0.0025, 0.0025), claimed(0.01, 0.01);
  for (int k = 0; k < 5000; ++k)
    s.add({std::sqrt(0.0025 + 0.09) * n(rng), std::sqrt(0.0025 + 0.01) * n(rng)}, prior, claimed);
  EXPECT_NEAR(s.scale().x(), 9.0, 1.5);
  EXPECT_NEAR(s.scale().y(), 1.0, 0.3);
  // Applied along a car heading 90 deg: the map's y is along it.
  const Eigen::Matrix2d C = scaled_along_across(Eigen::Matrix2d::Identity() * 0.01, M_PI / 2, {9.0, 1.0});
  EXPECT_NEAR(C(1, 1), 0.09, 1e-12);
  EXPECT_NEAR(C(0, 0), 0.01, 1e-12);
}

}  // namespace
}  // namespace lidarloop
