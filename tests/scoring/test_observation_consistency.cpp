// Map observations checked one by one against a known truth: an error of exactly one sigma gives NEES 1
// on its axis, the heading is compared with the truth turned by the mount yaw, an intensity
// observation's heading coupling is the truth's side, and an axis the observation does not constrain
// is left out.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "scoring/observation_consistency.hpp"

namespace lidarloop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The car drives north (yaw pi/2) along x = 5 at 10 m/s for 2 s.
std::vector<PoseStamped> north() {
  std::vector<PoseStamped> truth;
  for (int k = 0; k <= 20; ++k) truth.push_back({int64_t(k) * 100'000'000, {5, 1.0 * k, M_PI / 2}});
  return truth;
}

TEST(ObservationConsistency, OneSigmaOffGivesOneOnItsAxis) {
  const double mount = 0.2 * M_PI / 180;
  MapObservation curbs;
  curbs.stamp_ns = 500'000'000;  // the truth is at (5, 5)
  // 0.1 m to the car's left (-x when heading north), the heading off by 0.001 rad beyond the mount's.
  curbs.pose = {4.9, 5.0, M_PI / 2 + mount + 0.001};
  curbs.covariance = Eigen::Vector3d(100 * 100, 0.1 * 0.1, 0.002 * 0.002).asDiagonal();
  const ObservationConsistency c = observation_consistency(north(), {curbs}, mount, 1.0);
  EXPECT_EQ(c.counts(0), 0u);  // along: sigma 100 m, not informative
  EXPECT_EQ(c.counts(1), 1u);
  // The axes are the observation's own, 0.26 deg off the truth's: cos of that is 1 - 1e-5.
  EXPECT_NEAR(c.mean_nees(1), 1.0, 1e-4);
  EXPECT_NEAR(c.rms_error(1), 0.1, 1e-5);
  EXPECT_NEAR(c.mean_nees(2), 0.25, 1e-6);  // half a sigma
  EXPECT_TRUE(std::isnan(c.mean_nees(0)));
}

TEST(ObservationConsistency, AnIntensityMatchAtAWrongHeadingIsJudgedWithItsCoupling) {
  // APS matched at a prior heading 1 deg off the truth: its answer lies J (psi_prior - psi) from the car,
  // here J = (12.5, 0) m/rad. An answer exactly there has no error.
  const double off = M_PI / 180;
  MapObservation aps;
  aps.stamp_ns = 1'000'000'000;  // the truth is at (5, 10)
  aps.yaw_coupling = Eigen::Vector2d(12.5, 0);
  aps.pose = {5 + 12.5 * off, 10, M_PI / 2 + off};
  aps.covariance = Eigen::Vector3d(0.05 * 0.05, kInf, kInf).asDiagonal();  // along only
  const ObservationConsistency exact = observation_consistency(north(), {aps}, 0, 1.0);
  EXPECT_EQ(exact.counts(0), 1u);
  EXPECT_EQ(exact.counts(1), 0u);
  EXPECT_EQ(exact.counts(2), 0u);
  EXPECT_NEAR(exact.mean_nees(0), 0, 1e-9);
  aps.pose.y += 0.1;  // 0.1 m further along: 2 sigma (in axes 1 deg off the truth's: cos 1 deg of it)
  EXPECT_NEAR(observation_consistency(north(), {aps}, 0, 1.0).mean_nees(0), 4.0 * std::pow(std::cos(off), 2), 1e-9);
  aps.stamp_ns = 3'000'000'000;  // after the truth ends: not judged
  EXPECT_EQ(observation_consistency(north(), {aps}, 0, 1.0).counts(0), 0u);
}

}  // namespace
}  // namespace lidarloop
