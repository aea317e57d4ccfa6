// CAN odometry against a known truth: exact wheel speeds and steering drift by nothing, a wheel-speed
// scale error of 1 % by 1 % of every stretch along the road and nothing across it.
#include <cmath>

#include <gtest/gtest.h>

#include "loop/odometry_drift.hpp"

namespace lidarloop {
namespace {

// 30 s east at 10 m/s, truth and CAN at 100 Hz, the wheels reading `scale` times the true speed.
struct StraightDrive {
  std::vector<TruthSample> truth;
  std::vector<CanFrame> can;
};
StraightDrive straight_drive(double scale) {
  constexpr double kSpeed = 10, kDt = 0.01;
  StraightDrive d;
  for (int k = 0; k <= 3000; ++k) {
    const int64_t t = int64_t(k) * 10'000'000;
    TruthSample s;
    s.stamp_ns = t;
    s.pose = {kSpeed * k * kDt, 0, 0};
    s.speed = kSpeed;
    d.truth.push_back(s);
    CanFrame f;
    f.stamp_ns = t;
    f.wheel_speed_mps = {kSpeed * scale, kSpeed * scale, kSpeed * scale, kSpeed * scale};
    d.can.push_back(f);
  }
  return d;
}

TEST(OdometryDrift, AScaleErrorShowsAlongTheRoadInProportionToTheLength) {
  const StraightDrive exact = straight_drive(1.0);
  for (const OdometryDrift& d : odometry_drift(exact.truth, exact.can, VehicleModelParams{}, 0.01, {10, 100})) {
    EXPECT_GT(d.stretches, 100u);
    EXPECT_LT(d.longitudinal_rms_m, 1e-9) << d.length_m;
    EXPECT_LT(d.lateral_rms_m, 1e-9) << d.length_m;
  }
  const StraightDrive fast = straight_drive(1.01);
  const std::vector<OdometryDrift> drift =
      odometry_drift(fast.truth, fast.can, VehicleModelParams{}, 0.01, {10, 100, 1000});
  ASSERT_EQ(drift.size(), 3u);
  EXPECT_NEAR(drift[0].longitudinal_rms_m, 0.1, 0.002);  // a stretch ends at the first sample 10 m on
  EXPECT_NEAR(drift[1].longitudinal_rms_m, 1.0, 0.002);
  EXPECT_LT(drift[0].lateral_rms_m, 1e-9);
  EXPECT_LT(drift[1].heading_rms_rad, 1e-12);
  EXPECT_EQ(drift[2].stretches, 0u);  // the drive is 300 m
  // One stretch a metre: 300 m less the length, give or take one at the ends.
  EXPECT_NEAR(double(drift[0].stretches), 290, 1);
  EXPECT_NEAR(double(drift[1].stretches), 200, 1);
}

}  // namespace
}  // namespace lidarloop
