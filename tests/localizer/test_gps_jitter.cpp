// The receiver's white noise learnt from its fix-to-fix jitter, under a bias that wanders and a jump.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "localizer/gps_jitter.hpp"

namespace lidarloop {
namespace {

TEST(GpsJitter, RecoversTheWhiteNoiseUnderAWanderingBias) {
  // Fixes at 10 Hz: a Gauss-Markov bias of 2 m (tau 120 s) plus 0.3 m of white noise per axis, heading
  // 1.5 deg of bias plus 1 deg white. The bias is 7 times the white noise; the estimate must see only
  // the white part.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0, 1);
  const double dt = 0.1, tau = 120, white = 0.3, white_yaw = 0.0175;
  const double phi = std::exp(-dt / tau), drive = std::sqrt(1 - phi * phi);
  Eigen::Vector3d bias(2.0, -1.0, 0.026), previous = Eigen::Vector3d::Zero();
  GpsJitterParams params;
  params.window = 1000;
  GpsJitter jitter(params);
  for (int k = 0; k < 3000; ++k) {
    bias = phi * bias + drive * Eigen::Vector3d(2.0 * n(rng), 2.0 * n(rng), 0.026 * n(rng));
    const Eigen::Vector3d error = bias + Eigen::Vector3d(white * n(rng), white * n(rng), white_yaw * n(rng));
    if (k > 0) jitter.add(error - previous);  // the motion itself cancels against odometry
    previous = error;
    if (k == 5) {
      EXPECT_FALSE(jitter.calibrated());
    }
  }
  ASSERT_TRUE(jitter.calibrated());
  EXPECT_NEAR(std::sqrt(jitter.white_variance().x()), white, 0.03 * white + 0.01);
  EXPECT_NEAR(std::sqrt(jitter.white_variance().z()), white_yaw, 0.05 * white_yaw);
}

TEST(GpsJitter, AJumpIsNotTakenForJitter) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 0.3);
  GpsJitter jitter;
  for (int k = 0; k < 200; ++k) jitter.add(Eigen::Vector3d(n(rng), n(rng), 0.01 * n(rng)));
  const Eigen::Vector3d before = jitter.white_variance();
  jitter.add(Eigen::Vector3d(4.0, -3.0, 0));  // multipath: 5 m at once
  EXPECT_EQ(jitter.white_variance(), before);
  jitter.add(Eigen::Vector3d(std::nan(""), 0, 0));
  EXPECT_EQ(jitter.white_variance(), before);
}

// Before it is calibrated the estimate has no level of its own to gate by: a jump among the first
// changes is refused against the median of those taken so far, not averaged in (averaged in, as before
// the median, this test's 5 m jump makes the estimate 0.56 m and, as the first change, 0.62 m).
TEST(GpsJitter, AJumpAmongTheFirstChangesIsNotTakenForJitter) {
  std::mt19937_64 rng(5);
  const double white = 0.3;
  std::normal_distribution<double> n(0, white * std::sqrt(2.0));  // a change is two fixes' noise
  GpsJitter jitter;
  for (int k = 0; k < 3; ++k) jitter.add(Eigen::Vector3d(n(rng), n(rng), 0.0));
  jitter.add(Eigen::Vector3d(4.0, -3.0, 0));
  for (int k = 0; k < 20; ++k) jitter.add(Eigen::Vector3d(n(rng), n(rng), 0.0));
  ASSERT_TRUE(jitter.calibrated());
  EXPECT_NEAR(std::sqrt(jitter.white_variance().x()), white, 0.1);
  // The very first change a jump: no median to meet then, screened out once there are enough.
  GpsJitter first;
  first.add(Eigen::Vector3d(4.0, -3.0, 0));
  for (int k = 0; k < 20; ++k) first.add(Eigen::Vector3d(n(rng), n(rng), 0.0));
  ASSERT_TRUE(first.calibrated());
  EXPECT_NEAR(std::sqrt(first.white_variance().x()), white, 0.1);
}

}  // namespace
}  // namespace lidarloop
