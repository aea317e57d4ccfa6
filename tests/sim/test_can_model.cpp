// CAN bus model: dead reckoning from its frames against a known circular drive, quantisation, noise,
// latency, dropouts and determinism; and the DBC file agreeing with the model's defaults.
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "sim/can_model.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr double kNsToS = 1e-9;
constexpr int kRearLeft = 2, kRearRight = 3;

// Ground truth the bus samples: four wheel speeds (FL, FR, RL, RR) and the steering wheel angle.
struct CanTruth {
  std::array<double, 4> wheel_speeds_mps{};
  double steering_wheel_angle_rad = 0;
};
using TruthAt = std::function<CanTruth(int64_t t_ns)>;

// Measures `frames` frames at the model's rate starting at t = 0, delivering as the simulation loop
// does, then flushes what is still in flight.
std::vector<CanFrame> run(const CanConfig& config, uint64_t seed, int frames, const TruthAt& truth) {
  CanModel can(config, seed);
  std::vector<CanFrame> out;
  for (int k = 0; k < frames; ++k) {
    const int64_t t = k * can.period_ns();
    const CanTruth x = truth(t);
    can.measure(t, x.wheel_speeds_mps, x.steering_wheel_angle_rad);
    for (const CanFrame& f : can.deliver(t)) out.push_back(f);
  }
  for (const CanFrame& f : can.deliver(std::numeric_limits<int64_t>::max())) out.push_back(f);
  return out;
}

TruthAt constant(const CanTruth& x) {
  return [x](int64_t) { return x; };
}

// --- Dead reckoning on a circle -------------------------------------------------------------------

// A car driving a circle at constant speed, kinematic bicycle relation (no slip): the instantaneous
// centre of rotation lies on the rear axle line, radius R from the rear axle centre.
constexpr double kWheelbase = 2.6, kSteeringRatio = 16, kTrack = 1.6;
constexpr double kCircleRadius = 30, kCircleSpeed = 8;
constexpr int64_t kDriveNs = 10'000'000'000;

CanTruth circle_truth() {
  const double yaw_rate = kCircleSpeed / kCircleRadius;
  const double inner = kCircleRadius - kTrack / 2, outer = kCircleRadius + kTrack / 2;  // left turn: left is inner
  CanTruth x;
  x.wheel_speeds_mps = {yaw_rate * std::hypot(kWheelbase, inner), yaw_rate * std::hypot(kWheelbase, outer),
                        yaw_rate * inner, yaw_rate * outer};
  x.steering_wheel_angle_rad = kSteeringRatio * std::atan(kWheelbase / kCircleRadius);
  return x;
}

struct DeadReckoning {
  Pose2d pose;
  double distance_m = 0;
};

// Odometry as a localizer would compute it from the bus, over [start, end): rear-axle speed = mean of
// the rear wheels, yaw rate from the bicycle model. Each frame's values hold until the next frame
// arrives, so a lost frame is bridged by its predecessor (and lost first frames by the first one
// that arrived): on a steady drive, losses cost nothing.
DeadReckoning dead_reckon(const std::vector<CanFrame>& frames, int64_t start_ns, int64_t end_ns) {
  DeadReckoning dr;
  for (size_t i = 0; i < frames.size(); ++i) {
    const int64_t from = i == 0 ? start_ns : frames[i].stamp_ns;
    const int64_t until = i + 1 < frames.size() ? frames[i + 1].stamp_ns : end_ns;
    const double dt = double(until - from) * kNsToS;
    const CanFrame& f = frames[i];
    const double v = 0.5 * (f.wheel_speed_mps[kRearLeft] + f.wheel_speed_mps[kRearRight]);
    const double yaw_rate = v * std::tan(f.steering_wheel_angle_rad / kSteeringRatio) / kWheelbase;
    // Midpoint heading: the chord direction of a constant-curvature step.
    const double mid_yaw = dr.pose.yaw + 0.5 * yaw_rate * dt;
    dr.pose.x += v * dt * std::cos(mid_yaw);
    dr.pose.y += v * dt * std::sin(mid_yaw);
    dr.pose.yaw += yaw_rate * dt;
    dr.distance_m += v * dt;
  }
  return dr;
}

struct DriveResult {
  double relative_distance_error = 0;  // (dead-reckoned - true) / true
  double relative_end_error = 0;       // end-position error / true distance
};

DriveResult drive_circle(const CanConfig& config, uint64_t seed) {
  const CanModel probe(config, seed);
  const int frames = int(kDriveNs / probe.period_ns());
  // Frames measured over [0, drive) arrive over [latency, drive + latency).
  const DeadReckoning dr =
      dead_reckon(run(config, seed, frames, constant(circle_truth())), config.latency_ns, kDriveNs + config.latency_ns);
  const double distance = kCircleSpeed * double(kDriveNs) * kNsToS;
  const double angle = distance / kCircleRadius;  // starting at the origin heading +x, turning left
  const double end_x = kCircleRadius * std::sin(angle), end_y = kCircleRadius * (1 - std::cos(angle));
  return {(dr.distance_m - distance) / distance, std::hypot(dr.pose.x - end_x, dr.pose.y - end_y) / distance};
}

constexpr double kDistanceTolerance = 0.001;  // 0.1 % of the distance driven

TEST(CanDeadReckoning, DistanceIsLongByTheScaleError) {
  for (double scale_error : {0.01, -0.01, 0.005}) {
    CanConfig config;
    config.wheel_speed_scale_error = scale_error;
    const DriveResult r = drive_circle(config, 11);
    EXPECT_NEAR(r.relative_distance_error, scale_error, kDistanceTolerance) << "scale error " << scale_error;
  }
}

TEST(CanDeadReckoning, WithoutScaleErrorTheEndPointIsReproduced) {
  CanConfig config;  // default noise, quantisation and latency
  config.wheel_speed_scale_error = 0;
  const DriveResult r = drive_circle(config, 12);
  EXPECT_NEAR(r.relative_distance_error, 0, kDistanceTolerance);
  EXPECT_LT(r.relative_end_error, kDistanceTolerance);
}

TEST(CanDeadReckoning, LostFramesAreBridgedOnASteadyDrive) {
  CanConfig config;
  config.wheel_speed_scale_error = 0;
  config.dropout_probability = 0.3;
  const DriveResult r = drive_circle(config, 13);
  EXPECT_NEAR(r.relative_distance_error, 0, kDistanceTolerance);
  EXPECT_LT(r.relative_end_error, kDistanceTolerance);
}

// --- Quantisation ---------------------------------------------------------------------------------

bool is_multiple(double value, double step) {
  constexpr double kRoundingSlack = 1e-6;  // in units of the step: floating-point error of round * step
  const double k = value / step;
  return std::abs(k - std::round(k)) < kRoundingSlack;
}

// Speeds sweeping through zero (reversing) and up to ~20 m/s; steering lock to lock.
CanTruth sweeping_truth(int64_t t_ns) {
  const double t = double(t_ns) * kNsToS;
  CanTruth x;
  for (int i = 0; i < 4; ++i) x.wheel_speeds_mps[i] = 20 * std::sin(0.3 * t + 0.1 * i) + 0.37 * i;
  x.steering_wheel_angle_rad = 8 * std::sin(0.7 * t);
  return x;
}

TEST(CanQuantisation, ValuesAreMultiplesOfTheResolution) {
  CanConfig config;
  config.steering_offset_rad = 0.0123;  // off the grid: the offset is quantised with the angle
  const std::vector<CanFrame> frames = run(config, 21, 3000, sweeping_truth);
  ASSERT_EQ(frames.size(), 3000u);
  for (const CanFrame& f : frames) {
    for (double v : f.wheel_speed_mps) {
      EXPECT_TRUE(is_multiple(v, config.wheel_speed_resolution_mps)) << v;
      EXPECT_GE(v, 0) << "a wheel-speed sensor reports a magnitude";
      EXPECT_FALSE(std::signbit(v)) << "no -0";
    }
    EXPECT_TRUE(is_multiple(f.steering_wheel_angle_rad, config.steering_resolution_rad)) << f.steering_wheel_angle_rad;
  }
}

TEST(CanQuantisation, ReversingReportsTheMagnitude) {
  CanConfig config;
  config.wheel_speed_noise_mps = 0;
  config.wheel_speed_scale_error = 0;
  const std::vector<CanFrame> frames = run(config, 22, 1, constant({{-3.0, -3.0, -2.5, -2.5}, 0}));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_DOUBLE_EQ(frames[0].wheel_speed_mps[0], 3.0);
  EXPECT_DOUBLE_EQ(frames[0].wheel_speed_mps[kRearLeft], 2.5);
}

TEST(CanQuantisation, ZeroResolutionMeansNoQuantisation) {
  CanConfig config;
  config.wheel_speed_resolution_mps = 0;
  config.wheel_speed_noise_mps = 0;
  config.wheel_speed_scale_error = 0.02;
  config.steering_resolution_rad = 0;
  config.steering_noise_rad = 0;
  config.steering_offset_rad = 0.05;
  const CanTruth truth{{5.123456, 6.2, 7.3, 8.4}, 0.987654};
  const std::vector<CanFrame> frames = run(config, 23, 1, constant(truth));
  ASSERT_EQ(frames.size(), 1u);
  for (int i = 0; i < 4; ++i) EXPECT_DOUBLE_EQ(frames[0].wheel_speed_mps[i], truth.wheel_speeds_mps[i] * 1.02);
  EXPECT_DOUBLE_EQ(frames[0].steering_wheel_angle_rad, truth.steering_wheel_angle_rad + 0.05);
}

// --- Noise ----------------------------------------------------------------------------------------

struct Moments {
  double mean = 0, std = 0;
};

Moments moments(const std::vector<double>& x) {
  Moments m;
  for (double v : x) m.mean += v;
  m.mean /= double(x.size());
  for (double v : x) m.std += (v - m.mean) * (v - m.mean);
  m.std = std::sqrt(m.std / double(x.size() - 1));
  return m;
}

// White noise plus uniform rounding error (Sheppard): sigma^2 + step^2 / 12, valid while sigma is
// not much smaller than the step.
double expected_std(double noise, double step) { return std::sqrt(noise * noise + step * step / 12); }

TEST(CanNoise, SpreadMatchesNoiseAndQuantisation) {
  constexpr int kFrames = 10000;
  constexpr double kStdTolerance = 0.10;  // relative; the estimate itself is good to ~0.4 %
  constexpr double kMeanSigmas = 5;       // mean within 5 standard errors of the truth
  // The second case has a coarse step, so that forgetting the rounding term would fail.
  for (const auto& [noise, step] : {std::pair{0.02, 0.01}, std::pair{0.03, 0.05}}) {
    CanConfig config;
    config.wheel_speed_scale_error = 0;
    config.wheel_speed_noise_mps = noise;
    config.wheel_speed_resolution_mps = step;
    config.steering_noise_rad = noise;
    config.steering_resolution_rad = step;
    config.steering_offset_rad = 0.1;
    const CanTruth truth{{12.3456, 12.3456, 12.3456, 12.3456}, 0.4321};
    const std::vector<CanFrame> frames = run(config, 31, kFrames, constant(truth));
    std::vector<double> speeds, angles;
    for (const CanFrame& f : frames) {
      speeds.insert(speeds.end(), f.wheel_speed_mps.begin(), f.wheel_speed_mps.end());
      angles.push_back(f.steering_wheel_angle_rad);
    }
    const double sigma = expected_std(noise, step);
    const Moments s = moments(speeds), a = moments(angles);
    EXPECT_NEAR(s.std / sigma, 1, kStdTolerance) << "wheel speed, noise " << noise << " step " << step;
    EXPECT_NEAR(a.std / sigma, 1, kStdTolerance) << "steering, noise " << noise << " step " << step;
    EXPECT_NEAR(s.mean, truth.wheel_speeds_mps[0], kMeanSigmas * sigma / std::sqrt(double(speeds.size())));
    EXPECT_NEAR(a.mean, truth.steering_wheel_angle_rad + config.steering_offset_rad,
                kMeanSigmas * sigma / std::sqrt(double(angles.size())));
  }
}

// --- Latency and delivery -------------------------------------------------------------------------

TEST(CanLatency, FrameArrivesExactlyAfterTheLatency) {
  CanConfig config;
  config.latency_ns = 25'000'000;
  CanModel can(config, 41);
  const int64_t t = 1'230'000'000;
  can.measure(t, {1, 1, 1, 1}, 0);
  EXPECT_TRUE(can.deliver(t).empty());
  EXPECT_TRUE(can.deliver(t + config.latency_ns - 1).empty());
  const std::vector<CanFrame> got = can.deliver(t + config.latency_ns);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].stamp_ns, t + config.latency_ns);
  EXPECT_TRUE(can.deliver(t + config.latency_ns).empty()) << "each frame is delivered once";
}

TEST(CanLatency, FramesArriveOldestFirstAsTheyComeDue) {
  CanConfig config;
  config.latency_ns = 35'000'000;  // longer than three periods: several frames in flight
  CanModel can(config, 42);
  const int64_t period = can.period_ns();
  for (int k = 0; k < 5; ++k) can.measure(k * period, {1, 1, 1, 1}, 0);
  const std::vector<CanFrame> first = can.deliver(2 * period + config.latency_ns);
  ASSERT_EQ(first.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(first[k].stamp_ns, k * period + config.latency_ns);
  const std::vector<CanFrame> rest = can.deliver(std::numeric_limits<int64_t>::max());
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_EQ(rest[0].stamp_ns, 3 * period + config.latency_ns);
}

TEST(CanLatency, ZeroLatencyDeliversAtOnce) {
  CanConfig config;
  config.latency_ns = 0;
  CanModel can(config, 43);
  can.measure(500, {1, 1, 1, 1}, 0);
  ASSERT_EQ(can.deliver(500).size(), 1u);
}

TEST(CanLatency, MeasuringBackInTimeIsRejected) {
  CanModel can(CanConfig{}, 44);
  can.measure(1'000'000, {1, 1, 1, 1}, 0);
  EXPECT_THROW(can.measure(0, {1, 1, 1, 1}, 0), std::logic_error);
}

// --- Dropouts -------------------------------------------------------------------------------------

TEST(CanDropout, DeliveredFractionAndUnchangedValues) {
  constexpr int kFrames = 10000;
  constexpr double kProbability = 0.2, kFractionTolerance = 0.02;  // 5 binomial sigmas
  CanConfig clean;
  CanConfig lossy = clean;
  lossy.dropout_probability = kProbability;
  const std::vector<CanFrame> all = run(clean, 51, kFrames, sweeping_truth);
  const std::vector<CanFrame> kept = run(lossy, 51, kFrames, sweeping_truth);
  ASSERT_EQ(all.size(), size_t(kFrames));
  EXPECT_NEAR(double(kept.size()) / kFrames, 1 - kProbability, kFractionTolerance);

  // Dropping a frame does not shift the noise of later frames: each kept frame equals the frame of
  // the same stamp in the run without dropouts, value for value.
  const int64_t period = CanModel(clean, 51).period_ns();
  for (const CanFrame& f : kept) {
    const CanFrame& g = all[size_t((f.stamp_ns - clean.latency_ns) / period)];
    ASSERT_EQ(f.stamp_ns, g.stamp_ns);
    EXPECT_EQ(f.wheel_speed_mps, g.wheel_speed_mps);
    EXPECT_EQ(f.steering_wheel_angle_rad, g.steering_wheel_angle_rad);
  }
}

// --- Determinism, configuration -------------------------------------------------------------------

bool same_frames(const std::vector<CanFrame>& a, const std::vector<CanFrame>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].stamp_ns != b[i].stamp_ns || a[i].wheel_speed_mps != b[i].wheel_speed_mps ||
        a[i].steering_wheel_angle_rad != b[i].steering_wheel_angle_rad)
      return false;
  return true;
}

TEST(CanDeterminism, SameSeedSameFrames) {
  CanConfig config;
  config.dropout_probability = 0.1;
  const std::vector<CanFrame> a = run(config, 61, 2000, sweeping_truth);
  EXPECT_TRUE(same_frames(a, run(config, 61, 2000, sweeping_truth)));
  EXPECT_FALSE(same_frames(a, run(config, 62, 2000, sweeping_truth)));
}

TEST(CanModelConfig, PeriodIsTheRoundedInverseRate) {
  const auto period = [](double rate_hz) {
    CanConfig config;
    config.rate_hz = rate_hz;
    return CanModel(config, 0).period_ns();
  };
  EXPECT_EQ(period(100), 10'000'000);
  EXPECT_EQ(period(3), 333'333'333);  // 333 333 333.3
  EXPECT_EQ(period(7), 142'857'143);  // 142 857 142.86
}

TEST(CanModelConfig, InvalidSettingsAreRejected) {
  const auto rejects = [](auto change) {
    CanConfig config;
    change(config);
    return [config] { CanModel can(config, 0); };
  };
  EXPECT_THROW(rejects([](CanConfig& c) { c.rate_hz = 0; })(), std::invalid_argument);
  EXPECT_THROW(rejects([](CanConfig& c) { c.wheel_speed_resolution_mps = -0.01; })(), std::invalid_argument);
  EXPECT_THROW(rejects([](CanConfig& c) { c.steering_noise_rad = -1; })(), std::invalid_argument);
  EXPECT_THROW(rejects([](CanConfig& c) { c.latency_ns = -1; })(), std::invalid_argument);
  EXPECT_THROW(rejects([](CanConfig& c) { c.dropout_probability = 1; })(), std::invalid_argument);
  EXPECT_NO_THROW(rejects([](CanConfig&) {})());
}

// --- The DBC documents what the model does --------------------------------------------------------

struct DbcSignal {
  int start_bit = 0, length = 0;
  bool little_endian = false, is_signed = false;
  double factor = 0, offset = 0;
  std::string unit;
};

// Signals of message `id` in a DBC file, by name (only the fields these tests need).
std::map<std::string, DbcSignal> dbc_signals(const std::string& path, int id) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  const std::regex message(R"re(^BO_ (\d+) \w+: *(\d+) \w+\s*$)re");
  const std::regex signal(
      R"re(^ SG_ (\w+) : (\d+)\|(\d+)@([01])([+-]) \(([-0-9.eE+]+),([-0-9.eE+]+)\) \[[^\]]*\] "([^"]*)" [\w,]+\s*$)re");
  std::map<std::string, DbcSignal> out;
  bool inside = false;
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_match(line, m, message)) {
      inside = std::stoi(m[1]) == id;
    } else if (inside && std::regex_match(line, m, signal)) {
      out[m[1]] = {std::stoi(m[2]), std::stoi(m[3]), m[4] == "1", m[5] == "-", std::stod(m[6]), std::stod(m[7]), m[8]};
    } else if (line.empty()) {
      inside = false;
    }
  }
  return out;
}

constexpr int kWheelSpeedsId = 0x4B0, kSteeringId = 0x025;

TEST(CanDbc, FactorsAreTheModelsDefaultResolutions) {
  const std::string path = test::data_path("assets/vehicle_can.dbc");
  const CanConfig defaults;
  const auto wheels = dbc_signals(path, kWheelSpeedsId);
  ASSERT_EQ(wheels.size(), 4u);
  int bit = 0;
  for (const char* name : {"WHEEL_SPEED_FL", "WHEEL_SPEED_FR", "WHEEL_SPEED_RL", "WHEEL_SPEED_RR"}) {
    ASSERT_TRUE(wheels.count(name)) << name;
    const DbcSignal& s = wheels.at(name);
    EXPECT_EQ(s.start_bit, bit) << name << ": FL, FR, RL, RR in order, as CanFrame";
    EXPECT_EQ(s.length, 16);
    EXPECT_TRUE(s.little_endian);
    EXPECT_FALSE(s.is_signed) << "a magnitude";
    EXPECT_DOUBLE_EQ(s.factor, defaults.wheel_speed_resolution_mps);
    EXPECT_EQ(s.unit, "m/s");
    bit += 16;
  }
  const auto steering = dbc_signals(path, kSteeringId);
  ASSERT_TRUE(steering.count("STEERING_WHEEL_ANGLE"));
  ASSERT_TRUE(steering.count("ROLLING_COUNTER"));
  const DbcSignal& angle = steering.at("STEERING_WHEEL_ANGLE");
  EXPECT_TRUE(angle.is_signed);
  EXPECT_TRUE(angle.little_endian);
  EXPECT_DOUBLE_EQ(angle.factor, defaults.steering_resolution_rad);
  EXPECT_EQ(angle.unit, "rad");
}

}  // namespace
}  // namespace lidarloop
