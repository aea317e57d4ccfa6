// Prediction with Eq. 19 from CAN and the Kalman filter on [x, y, psi] and the GPS's bias: with GPS
// alone the filtered pose beats the raw low-cost GPS, a curb observation pulls the pose where it says,
// and the GPS's bias is learnt from the map.
#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "localizer/pose_filter.hpp"
#include "sim/can_model.hpp"
#include "sim/gps_model.hpp"
#include "sim/vehicle_model.hpp"

namespace lidarloop {
namespace {

TEST(PoseFilter, PredictionFromCanFollowsTheTrueCircle) {
  // The simulator's Eq. 19 car at 10 m/s with constant steering; the localizer's own predictor fed
  // with the true speed and wheel angle must stay on the same circle.
  const VehicleParams vp;
  VehicleModel car(vp, VehicleModel::state_at(vp, {0, 0, 0}, 10.0));
  MotionPredictor predictor(VehicleModelParams{});
  Pose2d predicted = car.rear_axle_pose();
  const double dt = 0.01;
  for (int k = 0; k < 1000; ++k) {  // 10 s
    for (int s = 0; s < 10; ++s) car.step({0.05, 0.0});
    const auto wheels = car.wheel_speeds();
    predicted = predictor.predict(predicted, 0.5 * (wheels[2] + wheels[3]), car.state().steer, dt);
  }
  const Pose2d truth = car.rear_axle_pose();
  EXPECT_LT(std::hypot(predicted.x - truth.x, predicted.y - truth.y), 0.5);  // 100 m of circle
  EXPECT_LT(std::abs(std::remainder(predicted.yaw - truth.yaw, 2 * M_PI)), 0.01);
}

// The low-cost GPS's error is mostly a slow Gauss-Markov bias, which no filter without another
// absolute reference can remove: with GPS alone, the gain is its white noise (position) and, much more,
// the heading, which the CAN odometry carries between fixes.
struct GpsOnly {
  double raw, filtered, raw_yaw, filtered_yaw;
};

// bias_state: the filter carries the GPS's bias as a state (the receiver's error model as it is);
// otherwise each fix is white noise of the receiver's reported variance (the localizer's default).
GpsOnly run_gps_only(uint64_t can_seed, uint64_t gps_seed, bool bias_state) {
  const VehicleParams vp;
  VehicleModel car(vp, VehicleModel::state_at(vp, {0, 0, 0}, 8.0));
  CanModel can(CanConfig{}, can_seed);
  const LocalFrame frame(Geodetic{31.28, 121.21, 0});
  GpsConfig gps_config;
  gps_config.bias_tau_s = 30.0;      // several bias periods in the run
  gps_config.antenna_xyz.setZero();  // fixes of the rear axle: this test is about the filter, not the lever arm
  GpsModel gps(gps_config, frame, gps_seed);
  MotionPredictor predictor(VehicleModelParams{});
  PoseFilter filter(car.rear_axle_pose(), Eigen::Vector3d(25, 25, 0.1).asDiagonal());
  auto sq = [](double v) { return v * v; };
  const Eigen::Vector3d bias(sq(gps_config.bias_sigma_m), sq(gps_config.bias_sigma_m),
                             sq(gps_config.heading_bias_sigma_rad));
  const Eigen::Vector3d white(sq(gps_config.white_sigma_m), sq(gps_config.white_sigma_m),
                              sq(gps_config.heading_white_sigma_rad));
  GpsErrorModel model;
  if (bias_state) {
    model.bias_variance = bias;
    model.white_variance = white;
    model.tau_s = Eigen::Vector3d(gps_config.bias_tau_s, gps_config.bias_tau_s, gps_config.heading_bias_tau_s);
  } else {
    model.white_variance = bias + white;
  }
  double raw2 = 0, filtered2 = 0, raw_yaw2 = 0, filtered_yaw2 = 0;
  int fixes = 0;
  CanFrame last{};
  const int64_t step = vp.step_ns;
  for (int64_t t = step; t <= 300'000'000'000; t += step) {  // 5 minutes, gentle slalom
    const double steer = 0.03 * std::sin(double(t) * 1e-9 * 0.2);
    car.step({steer, 0.0});
    if (t % can.period_ns() == 0) can.measure(t, car.wheel_speeds(), car.steering_wheel_angle());
    for (const CanFrame& f : can.deliver(t)) {
      const double v = 0.5 * (f.wheel_speed_mps[2] + f.wheel_speed_mps[3]);
      const double dt = last.stamp_ns ? double(f.stamp_ns - last.stamp_ns) * 1e-9 : 0.01;
      const Pose2d predicted =
          predictor.predict(filter.pose(), v, f.steering_wheel_angle_rad / VehicleModelParams{}.steering_ratio, dt);
      filter.predict(predicted, v * dt, dt);
      last = f;
    }
    if (t % gps.period_ns() == 0) {
      const Pose2d truth = car.rear_axle_pose();
      const GpsFix fix = gps.sample(t, truth);
      const Eigen::Vector2d z = frame.to_local(fix.lat_deg, fix.lon_deg);
      filter.update_gps({z.x(), z.y(), fix.heading_rad}, model);
      const Pose2d est = filter.pose();
      raw2 += (z - Eigen::Vector2d(truth.x, truth.y)).squaredNorm();
      filtered2 += std::pow(est.x - truth.x, 2) + std::pow(est.y - truth.y, 2);
      raw_yaw2 += std::pow(std::remainder(fix.heading_rad - truth.yaw, 2 * M_PI), 2);
      filtered_yaw2 += std::pow(std::remainder(est.yaw - truth.yaw, 2 * M_PI), 2);
      ++fixes;
    }
  }
  return {std::sqrt(raw2 / fixes), std::sqrt(filtered2 / fixes), std::sqrt(raw_yaw2 / fixes),
          std::sqrt(filtered_yaw2 / fixes)};
}

TEST(PoseFilter, WithGpsAloneTheEstimateBeatsRawGps) {
  for (auto [can_seed, gps_seed] : {std::pair<uint64_t, uint64_t>{5, 6}, {7, 8}, {9, 10}}) {
    const GpsOnly r = run_gps_only(can_seed, gps_seed, false);
    const GpsOnly b = run_gps_only(can_seed, gps_seed, true);
    std::cout << "[ figures  ] position RMSE: raw GPS " << r.raw << " m, filtered " << r.filtered << " m (bias state "
              << b.filtered << " m); heading RMSE: raw " << r.raw_yaw * 180 / M_PI << " deg, filtered "
              << r.filtered_yaw * 180 / M_PI << " deg (bias state " << b.filtered_yaw * 180 / M_PI << " deg)\n";
    EXPECT_LT(r.filtered, r.raw);
    EXPECT_LT(r.filtered_yaw, 0.8 * r.raw_yaw);
    // With the bias a state, the track of fixes (whose bias changes slowly) tells the heading; taken as
    // white noise, the fixes pull the pose about. Its position is no better than raw on every seed:
    // the filter lends part of the CAN's 0.5 % tyre-radius error to the bias.
    EXPECT_LT(b.filtered_yaw, 0.6 * r.filtered_yaw);
  }
}

GpsErrorModel low_cost_gps() {
  GpsErrorModel m;
  m.bias_variance = Eigen::Vector3d(4.0, 4.0, 1e-3);
  m.white_variance = Eigen::Vector3d(0.16, 0.16, 3e-4);
  m.tau_s = Eigen::Vector3d(60, 60, 60);
  return m;
}

TEST(PoseFilter, TheGpsBiasIsLearntWhereTheMapPinsThePoseAndKeptWhereItDoesNot) {
  // A car driving east at 10 m/s; every fix is off by the same (2, -1.5) m (a bias), 10 Hz. For 10 s a
  // curb match (10 cm) pins the pose; then the curbs are hidden for 5 s. The filter must have learnt the
  // bias and, with the map gone, keep the car where it is, not follow the fixes to the bias.
  const Eigen::Vector2d bias(2.0, -1.5);
  const GpsErrorModel gps = low_cost_gps();
  PoseFilter filter = PoseFilter::from_gps_fix(Eigen::Vector3d(bias.x(), bias.y(), 0), gps);
  double worst_unpinned = 0;
  for (int k = 1; k <= 150; ++k) {
    const double x = k;  // 1 m per 0.1 s
    filter.predict({filter.pose().x + 1.0, filter.pose().y, filter.pose().yaw}, 1.0, 0.1);
    filter.update_gps(Eigen::Vector3d(x + bias.x(), bias.y(), 0), gps);
    if (k <= 100) {
      filter.update_curb({x, 0, 0}, Eigen::Vector3d(0.01, 0.01, 1e-5).asDiagonal());
    } else {
      worst_unpinned = std::max(worst_unpinned, std::hypot(filter.pose().x - x, filter.pose().y));
    }
    if (k == 100) {
      EXPECT_NEAR(filter.gps_bias().x(), bias.x(), 0.1);
      EXPECT_NEAR(filter.gps_bias().y(), bias.y(), 0.1);
      EXPECT_LT(filter.gps_bias_covariance()(0, 0), 0.05);
    }
  }
  EXPECT_LT(worst_unpinned, 0.3);  // the bias itself is 2.5 m
}

TEST(PoseFilter, AColdStartTiesThePoseToTheBiasSoOneMapMatchRevealsIt) {
  // The first fix is 3 m east of the car: the filter starts there, and one confident map match then
  // tells both where the car is and that the receiver is 3 m east.
  const GpsErrorModel gps = low_cost_gps();
  PoseFilter filter = PoseFilter::from_gps_fix(Eigen::Vector3d(13, 5, 0.02), gps);
  EXPECT_NEAR(filter.covariance()(0, 0), 4.16, 1e-9);  // bias and white together
  filter.update_curb({10, 5, 0.0}, Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal());
  EXPECT_NEAR(filter.pose().x, 10, 0.01);
  EXPECT_NEAR(filter.gps_bias().x(), 3 * 4.0 / 4.16, 0.01);  // the fix's error, less its white share
  EXPECT_NEAR(filter.gps_bias().y(), 0, 1e-9);
}

TEST(PoseFilter, ASearchThatPlacesTheCarOnlyAcrossTheRoadLeavesItsPlaceAlongTheRoadAsUnknown) {
  // A cold start on a road running east: every scan, a search places the car across the road (10 cm)
  // and not along it, and two fixes come in between. No one measures the position along the road but
  // the GPS, whose bias is 2 m: the doubt along the road must stay at the GPS's.
  const GpsErrorModel gps = low_cost_gps();
  PoseFilter filter = PoseFilter::from_gps_fix(Eigen::Vector3d(1, 0.5, 0), gps);
  for (int scan = 0; scan < 50; ++scan) {
    for (int fix = 0; fix < 2; ++fix) filter.update_gps(Eigen::Vector3d(1, 0.5, 0), gps);
    const Eigen::Matrix3d placed = Eigen::Vector3d(filter.covariance()(0, 0), 0.01, 1e-5).asDiagonal();
    filter.reset_pose({filter.pose().x, 0.0, 0.0}, placed, {Eigen::Vector2d::UnitX(), false});
  }
  EXPECT_GT(filter.covariance()(0, 0), 0.9 * 4.0);
  EXPECT_NEAR(filter.covariance()(1, 1), 0.01, 1e-12);
  // A search that places the car on both axes: the bias starts over from its stationary doubt.
  filter.reset_pose({0, 0, 0}, Eigen::Vector3d(0.01, 0.01, 1e-5).asDiagonal());
  EXPECT_NEAR(filter.gps_bias_covariance()(0, 0), 4.0, 1e-12);
  EXPECT_NEAR(filter.covariance()(0, 0), 0.01, 1e-12);
}

// The LiDAR is truly turned 0.25 deg left of its nominal mount (2.5 times the calibration's stated
// 0.1 deg), so every curb match says the car heads 0.25 deg further left than it does. Driven by exact
// odometry along that heading, the car would drift across the road by the mount yaw times the
// distance, and the curbs say it does not: from that the filter learns the mount, through a bend and
// the straights either side, to within 0.03 deg in 20 s, and the car's heading with it. Without the
// state the car's heading is off by the whole mount yaw.
struct MountRun {
  double mount_yaw_at_20s, car_heading_error_at_20s, mount_sigma_at_20s;
};

MountRun drive_with_turned_lidar(double mount_yaw, double prior_sigma) {
  PoseFilterParams params;
  params.mount_yaw_sigma_rad = prior_sigma;
  params.position_per_sqrt_m = 0.005;  // odometry as good as a car's CAN, not the suite's default
  params.position_per_sqrt_s = 0.01;
  const double v = 10, dt = 0.01, lateral_sigma = 0.03, along_sigma = 2.0, yaw_sigma = 0.05 * M_PI / 180;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> unit;
  Pose2d truth{0, 0, 0};
  PoseFilter filter(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal(), params);
  MountRun out{};
  for (int k = 1; k <= 2000; ++k) {  // 20 s: 5 s east, a 90 deg left bend over 10 s, 5 s north
    const double t = k * dt, yaw_rate = t > 5 && t <= 15 ? M_PI / 2 / 10 : 0.0;
    const Pose2d step{v * dt, 0, yaw_rate * dt};
    truth = truth.compose(step);
    filter.predict(filter.car_pose().compose(step), v * dt, dt);
    if (k % 10 == 0) {  // a curb match every scan, of the nominal frame: psi + mount yaw
      const Eigen::Rotation2Dd to_map(truth.yaw);
      const Eigen::Vector2d noise = to_map * Eigen::Vector2d(along_sigma * unit(rng), lateral_sigma * unit(rng));
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      R.topLeftCorner<2, 2>() = to_map.toRotationMatrix() *
                                Eigen::Vector2d(along_sigma * along_sigma, lateral_sigma * lateral_sigma).asDiagonal() *
                                to_map.toRotationMatrix().transpose();
      R(2, 2) = yaw_sigma * yaw_sigma;
      filter.update_curb({truth.x + noise.x(), truth.y + noise.y(), truth.yaw + mount_yaw + yaw_sigma * unit(rng)}, R);
    }
  }
  out.mount_yaw_at_20s = filter.mount_yaw();
  out.car_heading_error_at_20s = std::remainder(filter.car_pose().yaw - truth.yaw, 2 * M_PI);
  out.mount_sigma_at_20s = std::sqrt(filter.mount_yaw_variance());
  return out;
}

TEST(PoseFilter, TheMountYawIsLearntFromTheDriftItWouldCauseAcrossTheRoad) {
  const double deg = M_PI / 180, mount = 0.25 * deg;
  const MountRun learnt = drive_with_turned_lidar(mount, 0.1 * deg);
  EXPECT_NEAR(learnt.mount_yaw_at_20s, mount, 0.03 * deg);
  EXPECT_LT(std::abs(learnt.car_heading_error_at_20s), 0.03 * deg);
  EXPECT_LT(learnt.mount_sigma_at_20s, 0.03 * deg);
  EXPECT_GT(learnt.mount_sigma_at_20s, 0.001 * deg);  // learnt from 200 matches, not to nothing
  const MountRun nominal = drive_with_turned_lidar(mount, 0);
  EXPECT_NEAR(nominal.car_heading_error_at_20s, mount, 0.03 * deg);  // the matches' heading, mount and all
}

// A parked car: GPS fixes say where it heads (white noise of 0.5 deg), the curbs say where the nominal
// frame heads, 0.3 deg more. The mount yaw is the difference, learnt from the two directly; a fix is then
// judged against the car's heading, not the map's.
TEST(PoseFilter, TheMountYawIsWhereTheMapsHeadingDiffersFromTheGpss) {
  const double deg = M_PI / 180, mount = 0.3 * deg;
  PoseFilterParams params;
  params.mount_yaw_sigma_rad = 1 * deg;
  GpsErrorModel gps;
  gps.white_variance = Eigen::Vector3d(0.25, 0.25, std::pow(0.5 * deg, 2));
  gps.bias_variance = Eigen::Vector3d(1e-6, 1e-6, 1e-10);
  gps.tau_s = Eigen::Vector3d::Constant(60);
  PoseFilter filter({10, 5, 0.5}, Eigen::Vector3d(1, 1, std::pow(2 * deg, 2)).asDiagonal(), params);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit;
  for (int k = 0; k < 300; ++k) {
    filter.predict(filter.car_pose(), 0, 0.1);
    filter.update_gps(Eigen::Vector3d(10, 5, 0.5 + 0.5 * deg * unit(rng)), gps);
    filter.update_curb({10, 5, 0.5 + mount + 0.02 * deg * unit(rng)},
                       Eigen::Vector3d(0.01, 0.01, std::pow(0.02 * deg, 2)).asDiagonal());
  }
  EXPECT_NEAR(filter.mount_yaw(), mount, 0.05 * deg);  // 300 fixes of 0.5 deg: 0.03 deg of noise
  EXPECT_NEAR(filter.car_pose().yaw, 0.5, 0.05 * deg);
  EXPECT_LT(std::sqrt(filter.mount_yaw_variance()), 0.05 * deg);
  EXPECT_NEAR(filter.gps_innovation({10, 5, 0.5})(2), 0, 0.05 * deg);
  const double fix_doubt = filter.gps_innovation_covariance(gps)(2, 2) - gps.white_variance(2);
  EXPECT_GT(fix_doubt, 0);
  EXPECT_LT(fix_doubt, std::pow(0.05 * deg, 2));  // the car's heading and the bias, both known by now
  // A search that places the car across the road and its heading keeps the mount yaw and its doubt.
  const double before = filter.mount_yaw_variance();
  filter.reset_pose({10, 5, 0.5 + mount}, Eigen::Vector3d(0.01, 0.01, 1e-6).asDiagonal(),
                    {Eigen::Vector2d::UnitX(), false});
  EXPECT_DOUBLE_EQ(filter.mount_yaw_variance(), before);
  EXPECT_NEAR(filter.mount_yaw(), mount, 0.05 * deg);
}

// The yaw rate's scale error: a quarter turn adds k^2 pi/2 to the heading's variance beyond what the
// same distance driven straight adds, in whatever steps it is taken.
TEST(PoseFilter, TheHeadingsDoubtGrowsWithTheAngleTurned) {
  PoseFilterParams params;
  params.yaw_per_sqrt_rad = 0.0063;
  PoseFilter straight({0, 0, 0}, Eigen::Matrix3d::Identity() * 1e-6, params);
  PoseFilter bend({0, 0, 0}, Eigen::Matrix3d::Identity() * 1e-6, params);
  for (int k = 0; k < 100; ++k) {
    straight.predict(straight.car_pose().compose({0.2, 0, 0}), 0.2, 0.02);
    bend.predict(bend.car_pose().compose({0.2, 0, M_PI / 200}), 0.2, 0.02);
  }
  EXPECT_NEAR(bend.pose().yaw, M_PI / 2, 1e-12);
  EXPECT_NEAR(bend.covariance()(2, 2) - straight.covariance()(2, 2), 0.0063 * 0.0063 * M_PI / 2, 1e-12);
}

TEST(PoseFilter, AConfidentCurbObservationPullsThePoseToIt) {
  PoseFilter filter({10, 0, 0.1}, Eigen::Vector3d(4, 4, 0.01).asDiagonal());
  filter.update_curb({11, -0.5, 0.12}, Eigen::Vector3d(0.01, 0.01, 1e-4).asDiagonal());
  EXPECT_NEAR(filter.pose().x, 11, 0.01);
  EXPECT_NEAR(filter.pose().y, -0.5, 0.01);
  EXPECT_NEAR(filter.pose().yaw, 0.12, 0.01);
  filter.update_intensity({11.3, -0.5}, Eigen::Vector2d(0.01, 0.01).asDiagonal());  // longitudinal from paint
  EXPECT_NEAR(filter.pose().x, 11.15, 0.02);  // two equally confident observations: halfway
  EXPECT_LT(filter.covariance()(0, 0), 0.01);
  // Angles are combined as angles across +-pi.
  PoseFilter wrap({0, 0, M_PI - 0.01}, Eigen::Vector3d(1, 1, 0.01).asDiagonal());
  wrap.update_curb({0, 0, -M_PI + 0.01}, Eigen::Vector3d(1, 1, 0.01).asDiagonal());
  EXPECT_NEAR(std::abs(wrap.pose().yaw), M_PI, 1e-6);
}

TEST(PoseFilter, AnIntensityMatchCoupledToTheHeadingCorrectsTheHeading) {
  // The car is at (10, 0) heading 0; the filter believes it heads 1 deg left, with 1 deg of doubt and
  // the position known to 1 cm. APS, matched at the believed heading on a line 12.5 m ahead, answers
  // p + J (psi_prior - psi) with J = (0, -12.5) m/rad: 0.22 m to the right.
  const double e = M_PI / 180;
  const Eigen::Vector2d J(0, -12.5);
  const Eigen::Vector2d z = Eigen::Vector2d(10, 0) + J * e;
  const Eigen::Matrix3d P = Eigen::Vector3d(1e-4, 1e-4, e * e).asDiagonal();
  const Eigen::Matrix2d R = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  PoseFilter coupled({10, 0, e}, P);
  coupled.update_intensity(z, R, J);
  // The heading takes most of the correction (its doubt is 22 cm at the line, the position's 1 cm).
  EXPECT_LT(std::abs(coupled.pose().yaw), 0.2 * e);
  EXPECT_NEAR(coupled.pose().y, 0.0, 0.02);
  // Without the coupling the position is dragged instead, and the heading stays wrong.
  PoseFilter plain({10, 0, e}, P);
  plain.update_intensity(z, R);
  EXPECT_NEAR(plain.pose().yaw, e, 1e-9);
  EXPECT_LT(plain.pose().y, -0.1);
  // Along one direction only (the lateral here), the same.
  PoseFilter along({10, 0, e}, P);
  along.update_intensity_along(z, R, {0, 1}, J);
  EXPECT_LT(std::abs(along.pose().yaw), 0.2 * e);
}

}  // namespace
}  // namespace lidarloop
