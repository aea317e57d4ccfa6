// Consistency (NEES), integrity (misleading frames, availability) and recovery from faults, on
// synthetic runs whose errors, covariances, bounds and `lost` flags are known by construction.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "loop/fault_events.hpp"
#include "scoring/error_plots.hpp"
#include "scoring/result_files.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int64_t kMs = 1'000'000;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Path straight_route() { return make_path({{0, 0}, {1000, 0}}, false); }

// A straight drive east at 10 m/s, 100 Hz, for `seconds`.
std::vector<TruthPose> straight_truth(double seconds) {
  std::vector<TruthPose> truth;
  for (int64_t t = 0; t <= int64_t(seconds * 1000) * kMs; t += 10 * kMs)
    truth.push_back({t, {10.0 * double(t) / 1e9, 0, 0}});
  return truth;
}

// Estimates at 10 Hz on the straight truth, `lateral_at(t_s)` m to its left, with a diagonal covariance
// of 0.1 m, bounds of 0.2 m and not lost unless `lost_at(t_s)`.
std::vector<EstimateRecord> estimates(double seconds, const std::function<double(double)>& lateral_at,
                                      const std::function<bool(double)>& lost_at) {
  std::vector<EstimateRecord> out;
  for (int64_t t = 0; t <= int64_t(seconds * 1000) * kMs; t += 100 * kMs) {
    const double s = double(t) / 1e9;
    EstimateRecord e;
    e.stamp_ns = t;
    e.pose = {10.0 * double(t) / 1e9, lateral_at(s), 0};  // as the truth's x: no round-off error
    e.covariance = Eigen::Vector3d(0.01, 0.01, 1e-4).asDiagonal();
    e.lost = lost_at(s);
    e.protection_lateral_m = e.protection_longitudinal_m = 0.2;
    out.push_back(e);
  }
  return out;
}

// The kidnap of the brief: at 10 s the estimate jumps 4 m and stays there until 11.5 s, `lost` raised
// at 10.4 s and cleared at 12 s (stamps are whole 100 ms steps; the comparisons are at 50 ms).
std::vector<EstimateRecord> kidnapped(double seconds = 20) {
  return estimates(
      seconds, [](double s) { return s > 9.95 && s < 11.45 ? 4.0 : 0.0; },
      [](double s) { return s > 10.35 && s < 11.95; });
}

FrameError frame(double lateral, double longitudinal, double bound_lat, double bound_long, bool lost) {
  FrameError f;
  f.lateral_m = lateral;
  f.longitudinal_m = longitudinal;
  f.protection_lateral_m = bound_lat;
  f.protection_longitudinal_m = bound_long;
  f.lost = lost;
  return f;
}

// N draws from the claimed covariance `p` around a truth heading 0.5 rad, scored against `claimed`.
std::vector<FrameError> drawn_errors(const Eigen::Matrix3d& p, const Eigen::Matrix3d& claimed, int n) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> normal(0, 1);
  const Eigen::Matrix3d l = p.llt().matrixL();
  const Pose2d truth{100, 50, 0.5};
  std::vector<FrameError> out;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = l * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    EstimateRecord e;
    e.pose = {truth.x + d.x(), truth.y + d.y(), truth.yaw + d.z()};
    e.covariance = claimed;
    out.push_back(estimate_error(truth, e));
  }
  return out;
}

TEST(Consistency, NeesOfErrorsDrawnFromTheCovarianceAveragesOnePerAxis) {
  // Correlated x-y so the rotation into the truth's frame matters.
  Eigen::Matrix3d p;
  p << 0.04, 0.015, 0, 0.015, 0.09, 0, 0, 0, 1e-4;
  constexpr int kN = 4000;
  // Each axis' NEES is chi-square(1) (mean 1, variance 2): the mean of kN has a standard deviation of
  // sqrt(2 / kN) = 0.022; 5 of them is a bound a correct scorer meets on any seed.
  const double tolerance = 5 * std::sqrt(2.0 / kN);
  const Consistency honest = consistency(drawn_errors(p, p, kN));
  EXPECT_NEAR(honest.mean_nees_lateral, 1.0, tolerance);
  EXPECT_NEAR(honest.mean_nees_longitudinal, 1.0, tolerance);
  EXPECT_NEAR(honest.mean_nees_heading, 1.0, tolerance);
  EXPECT_EQ(honest.frames, size_t(kN));
  // 0.27 % beyond 3 sigma per axis, about 0.8 % on any of three.
  EXPECT_LT(honest.beyond_3_sigma_lateral, 0.01);
  EXPECT_LT(honest.beyond_3_sigma_any, 0.02);
  // Claiming a quarter of the variance (half the sigma) quadruples the NEES, and 13.4 % of the errors
  // (|e| > 1.5 true sigma) are beyond the claimed 3 sigma.
  const Consistency over = consistency(drawn_errors(p, p / 4, kN));
  EXPECT_NEAR(over.mean_nees_lateral, 4.0, 4 * tolerance);
  EXPECT_NEAR(over.mean_nees_longitudinal, 4.0, 4 * tolerance);
  EXPECT_NEAR(over.mean_nees_heading, 4.0, 4 * tolerance);
  const double beyond = std::erfc(1.5 / std::sqrt(2.0));  // P(|z| > 1.5)
  EXPECT_NEAR(over.beyond_3_sigma_lateral, beyond, 5 * std::sqrt(beyond * (1 - beyond) / kN));
}

TEST(Consistency, TheCovarianceIsRotatedIntoTheTruthsFrame) {
  EstimateRecord e;
  e.covariance = Eigen::Vector3d(0.04, 0, 0).asDiagonal();  // variance along the map's x (east) only
  // Heading north (90 deg), east is the car's right: lateral. No longitudinal or heading variance.
  const FrameError north = estimate_error({0, 0, kPi / 2}, e);
  EXPECT_NEAR(north.sigma_lateral_m, 0.2, 1e-12);
  EXPECT_TRUE(std::isnan(north.sigma_longitudinal_m));
  EXPECT_TRUE(std::isnan(north.sigma_heading_rad));
  // Heading east, the same variance is longitudinal.
  const FrameError east = estimate_error({0, 0, 0}, e);
  EXPECT_NEAR(east.sigma_longitudinal_m, 0.2, 1e-12);
  EXPECT_TRUE(std::isnan(east.sigma_lateral_m));
  // Any heading and correlation: the diagonal of R^T P R.
  e.covariance << 0.04, 0.015, 0, 0.015, 0.09, 0, 0, 0, 0.01;
  const double yaw = 0.7;
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  const Eigen::Matrix2d vehicle = r.transpose() * e.covariance.topLeftCorner<2, 2>() * r;
  const FrameError f = estimate_error({3, 4, yaw}, e);
  EXPECT_NEAR(f.sigma_longitudinal_m, std::sqrt(vehicle(0, 0)), 1e-12);
  EXPECT_NEAR(f.sigma_lateral_m, std::sqrt(vehicle(1, 1)), 1e-12);
  EXPECT_NEAR(f.sigma_heading_rad, 0.1, 1e-12);
  // Lost frames and axes without variance do not count; none left is NaN (a TUM file's estimates).
  std::vector<FrameError> frames = {frame(0.2, 0, kNaN, kNaN, false), frame(5, 0, kNaN, kNaN, true)};
  frames[0].sigma_lateral_m = frames[1].sigma_lateral_m = 0.1;
  const Consistency c = consistency(frames);
  EXPECT_DOUBLE_EQ(c.mean_nees_lateral, 4.0);
  EXPECT_TRUE(std::isnan(c.mean_nees_longitudinal));
  EXPECT_TRUE(std::isnan(c.beyond_3_sigma_any));
  EXPECT_EQ(c.frames, 0u);
}

TEST(Integrity, MisleadingFramesAreErrorsBeyondTheBoundWhileNotLost) {
  const std::vector<FrameError> frames = {
      frame(0.1, 0.1, 0.2, 0.2, false),    // within
      frame(0.3, 0.1, 0.2, 0.2, false),    // lateral beyond: misleading
      frame(0.3, 0.1, 0.2, 0.2, true),     // beyond, but lost: it said so
      frame(0.1, -0.5, 0.2, 0.4, false),   // longitudinal beyond: misleading
      frame(9.0, 9.0, kNaN, kNaN, false),  // no bounds: not counted
      frame(9.0, 9.0, kInf, kInf, true),   // lost, bounds "anywhere": counted, never exceeded
  };
  const Integrity in = integrity(frames, 0.29, 0.29);
  EXPECT_EQ(in.frames_with_bounds, 5u);
  EXPECT_EQ(in.misleading_frames, 2u);
  EXPECT_DOUBLE_EQ(in.misleading_fraction, 0.4);
  // Available: not lost and both bounds under the alert limits: frames 0 and 1 (0.2 < 0.29), not 3
  // (0.4), 2 and 5 (lost) or 4 (no bound); of all 6 scored frames.
  EXPECT_DOUBLE_EQ(in.availability, 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(integrity(frames, 0.5, 0.5).availability, 3.0 / 6.0);
  EXPECT_DOUBLE_EQ(integrity(frames, 0.1, 0.5).availability, 0.0);
  const Integrity none = integrity({frame(1, 1, kNaN, kNaN, false)}, 0.29, 0.29);
  EXPECT_EQ(none.frames_with_bounds, 0u);
  EXPECT_TRUE(std::isnan(none.misleading_fraction));
  EXPECT_DOUBLE_EQ(none.availability, 0.0);
}

TEST(Recovery, AKidnapIsMeasuredFromItsEventAndKeptOutOfTheAccuracy) {
  const std::vector<FaultEvent> events = {{10'000 * kMs, "kidnap"}, {0, "start"}};  // any order
  PassThresholds t;
  t.recovery = PassThresholds::Recovery{};  // the suite's defaults: 0.3 m within 3 s, lost within 1 s
  const ScoredRun run = score(straight_truth(20), kidnapped(), straight_route(), t, "m", "s", events);
  const Metrics& m = run.metrics;
  ASSERT_EQ(m.recovery.size(), 2u);
  EXPECT_EQ(m.recovery[0].event.what, "start");
  EXPECT_NEAR(m.recovery[0].converged_after_s, 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(m.recovery[0].lost_raised_after_s));
  EXPECT_EQ(m.recovery[1].event.what, "kidnap");
  EXPECT_NEAR(m.recovery[1].converged_after_s, 1.5, 1e-9);
  EXPECT_NEAR(m.recovery[1].lost_raised_after_s, 0.4, 1e-9);
  EXPECT_NEAR(m.recovery[1].lost_cleared_after_s, 2.0, 1e-9);
  // [10 s, 13 s] at 10 Hz: 31 recovery frames, out of the RMSE and maxima but scored, so counted in
  // integrity: the 4 m frames 10.0 and 10.1-10.3 s (not yet lost) would be misleading (bounds 0.2 m),
  // but `lost` came 0.4 s after the kidnap, within the 1 s time to alert: they await it, apart.
  EXPECT_EQ(m.frames, 201u);
  EXPECT_EQ(m.recovery_frames, 31u);
  EXPECT_DOUBLE_EQ(m.lateral_rmse_m, 0.0);
  EXPECT_DOUBLE_EQ(m.max_position_error_m, 0.0);
  EXPECT_EQ(m.integrity.misleading_frames, 0u);
  EXPECT_EQ(m.integrity.frames_awaiting_alert, 4u);
  EXPECT_EQ(m.integrity.misleading_awaiting_alert, 4u);
  EXPECT_DOUBLE_EQ(m.consistency.mean_nees_lateral, 0.0);  // every other frame not lost is exact
  // An alert later than the time to alert leaves them misleading, and in NEES.
  PassThresholds late = t;
  late.recovery->lost_within_s = 0.3;
  const Metrics alerted_late = score(straight_truth(20), kidnapped(), straight_route(), late, "m", "s", events).metrics;
  EXPECT_EQ(alerted_late.integrity.misleading_frames, 4u);
  EXPECT_EQ(alerted_late.integrity.frames_awaiting_alert, 0u);
  EXPECT_GT(alerted_late.consistency.mean_nees_lateral, 1.0);
  EXPECT_TRUE(m.pass) << testing::PrintToString(m.failures);
  // Unset, the same figures are measured, not gated, and every frame is in the accuracy.
  const Metrics ungated = score(straight_truth(20), kidnapped(), straight_route(), {}, "m", "s", events).metrics;
  EXPECT_NEAR(ungated.recovery[1].converged_after_s, 1.5, 1e-9);
  EXPECT_EQ(ungated.recovery_frames, 0u);
  EXPECT_DOUBLE_EQ(ungated.max_position_error_m, 4.0);

  // Fails each criterion tightened below its figure.
  auto failures = [&](const PassThresholds& thresholds, const std::vector<EstimateRecord>& est) {
    return score(straight_truth(20), est, straight_route(), thresholds, "m", "s", events).metrics.failures;
  };
  t.recovery->within_s = 1.0;
  EXPECT_EQ(failures(t, kidnapped()), std::vector<std::string>{"kidnap at 10.00 s: converged after 1.500 s > 1.000 s"});
  t.recovery = PassThresholds::Recovery{};
  t.recovery->lost_within_s = 0.3;
  EXPECT_EQ(failures(t, kidnapped()),
            std::vector<std::string>{"kidnap at 10.00 s: lost raised after 0.400 s > 0.300 s"});
  t.recovery = PassThresholds::Recovery{};
  const auto never_cleared = estimates(
      20, [](double s) { return s > 9.95 && s < 11.45 ? 4.0 : 0.0; }, [](double s) { return s > 10.35; });
  EXPECT_EQ(failures(t, never_cleared), std::vector<std::string>{"kidnap at 10.00 s: lost was never cleared"});
  const auto never_raised = estimates(
      20, [](double s) { return s > 9.95 && s < 11.45 ? 4.0 : 0.0; }, [](double) { return false; });
  EXPECT_EQ(failures(t, never_raised), std::vector<std::string>{"kidnap at 10.00 s: lost was never raised"});
  const auto never_converged = estimates(
      20, [](double s) { return s > 9.95 ? 4.0 : 0.0; }, [](double s) { return s > 10.35 && s < 11.95; });
  EXPECT_EQ(failures(t, never_converged).front(), "kidnap at 10.00 s: the position error never stayed under 0.300 m");
  // A cold start may be lost from its first frame; it must clear.
  const auto cold = estimates(
      20, [](double s) { return s < 1.05 ? 3.0 : 0.0; }, [](double s) { return s < 0.55; });
  const Metrics start = score(straight_truth(20), cold, straight_route(), t, "m", "s", {{0, "start"}}).metrics;
  EXPECT_TRUE(start.pass) << testing::PrintToString(start.failures);
  EXPECT_NEAR(start.recovery[0].converged_after_s, 1.1, 1e-9);
  EXPECT_NEAR(start.recovery[0].lost_raised_after_s, 0.0, 1e-9);
  EXPECT_NEAR(start.recovery[0].lost_cleared_after_s, 0.6, 1e-9);
  const auto stuck = estimates(
      20, [](double) { return 0.0; }, [](double) { return true; });
  EXPECT_EQ(score(straight_truth(20), stuck, straight_route(), t, "m", "s", {{0, "start"}}).metrics.failures,
            std::vector<std::string>{"start at 0.00 s: lost was never cleared"});
}

TEST(Recovery, AGpsJumpBackNeedsNoLostButAJumpDoes) {
  // The localizer held the map's pose: never lost, never off.
  const auto steady = estimates(
      20, [](double) { return 0.0; }, [](double) { return false; });
  PassThresholds t;
  t.recovery = PassThresholds::Recovery{};
  auto failures = [&](const std::string& what) {
    return score(straight_truth(20), steady, straight_route(), t, "m", "s", {{0, "start"}, {10'000 * kMs, what}})
        .metrics.failures;
  };
  EXPECT_EQ(failures("gps jump back"), std::vector<std::string>{});
  EXPECT_EQ(failures("gps jump"), std::vector<std::string>{"gps jump at 10.00 s: lost was never raised"});
}

TEST(PassGates, EachIntegrityAndConsistencyKeyGatesThePass) {
  // Lateral error 0.1 m against sigma 0.1 m: NEES 1 lateral, 0 on the others; bounds 0.2 m never
  // exceeded; available under the default 0.29 m alert limits.
  const auto est = estimates(
      5, [](double) { return 0.1; }, [](double) { return false; });
  auto failures = [&](const PassThresholds& t, const std::vector<EstimateRecord>& e) {
    return score(straight_truth(5), e, straight_route(), t, "m", "s").metrics.failures;
  };
  using Failures = std::vector<std::string>;
  PassThresholds t;
  t.max_misleading_fraction = 0.001;
  t.min_availability = 0.99;
  t.min_mean_nees = 0.0;
  t.max_mean_nees = 2.0;
  EXPECT_EQ(failures(t, est), Failures{});
  auto misleading = est;
  for (size_t i = 0; i < 2; ++i) misleading[i].protection_lateral_m = 0.05;
  EXPECT_EQ(failures(t, misleading), Failures{"misleading frames 3.922 % > 0.100 %"});  // 2 of 51
  PassThresholds tight = t;
  tight.alert_limit_lateral_m = 0.15;  // under every bound: nothing available
  EXPECT_EQ(failures(tight, est), Failures{"availability 0.000 < 0.990"});
  tight = t;
  tight.alert_limit_longitudinal_m = 0.15;
  EXPECT_EQ(failures(tight, est), Failures{"availability 0.000 < 0.990"});
  tight = t;
  tight.max_mean_nees = 0.5;
  EXPECT_EQ(failures(tight, est), Failures{"mean NEES lateral 1.000 > 0.500"});
  tight = t;
  tight.min_mean_nees = 0.5;  // longitudinal and heading errors are 0: NEES 0
  EXPECT_EQ(failures(tight, est),
            (Failures{"mean NEES longitudinal 0.000 < 0.500", "mean NEES heading 0.000 < 0.500"}));
  // No covariance, no bounds (a TUM file): an integrity or consistency gate cannot hold.
  auto bare = est;
  for (auto& e : bare) {
    e.covariance.setZero();
    e.protection_lateral_m = e.protection_longitudinal_m = kNaN;
  }
  EXPECT_EQ(failures(t, bare).size(), 8u);  // misleading, availability, min and max NEES on each axis
}

TEST(FaultEvents, TheStartKidnapsAndTimedGpsJumpsInTimeOrder) {
  Scenario s;
  s.duration_s = 60;
  // Each at the scan start nearest its time: 10.04 s at 10.0 s, 30.06 s at 30.1 s.
  s.kidnaps = {{30.06, {3, 0}, 0}, {10.04, {0, 2}, 0, KidnapMoves::car}};
  GpsZone jump{GpsZone::Kind::multipath};
  jump.from_ns = 20'000 * kMs, jump.to_ns = 25'000 * kMs, jump.jump_m = {5, 0};
  GpsZone spatial = jump;  // where the car enters it: not known from the scenario
  spatial.radius_m = 30;
  GpsZone outage{GpsZone::Kind::outage};  // no fix is not a jump
  outage.from_ns = 40'000 * kMs, outage.to_ns = 45'000 * kMs;
  GpsZone from_start = jump, endless = jump;  // in force at the start; never jumping back in the run
  from_start.from_ns = 0, from_start.to_ns = 5'000 * kMs;
  endless.from_ns = 50'000 * kMs, endless.to_ns = INT64_MAX;
  s.gps.zones = {jump, spatial, outage, from_start, endless};
  const std::vector<FaultEvent> events = fault_events(s, 10 * kMs);  // the first truth sample
  const std::vector<std::pair<int64_t, std::string>> expected = {
      {10 * kMs, "start"},        {5'000 * kMs, "gps jump back"},  {10'000 * kMs, "kidnap"},
      {20'000 * kMs, "gps jump"}, {25'000 * kMs, "gps jump back"}, {30'100 * kMs, "kidnap"},
      {50'000 * kMs, "gps jump"}};
  ASSERT_EQ(events.size(), expected.size());
  for (size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].stamp_ns, expected[i].first) << i;
    EXPECT_EQ(events[i].what, expected[i].second) << i;
  }
}

TEST(PassYaml, TheNewKeysAreReadStrictlyWithFileLineAndColumn) {
  const std::string scenario = R"(world: campus
duration_s: 30
ego: {route: {road: loop, lane: right}}
pass:
  max_misleading_fraction: 0.001
  min_availability: 0.9
  alert_limit_lateral_m: 0.5
  min_mean_nees: 0.5
  max_mean_nees: 2
  recovery: {position_m: 0.25, within_s: 4}
)";
  const PassThresholds p = parse_scenario(scenario, "ok.yaml").pass;
  EXPECT_EQ(p.max_misleading_fraction, 0.001);
  EXPECT_EQ(p.min_availability, 0.9);
  EXPECT_EQ(p.alert_limit_lateral_m, 0.5);
  EXPECT_EQ(p.alert_limit_longitudinal_m, kLocalStreetAlertLimit_m);  // Reid et al.'s local streets
  EXPECT_EQ(p.min_mean_nees, 0.5);
  EXPECT_EQ(p.max_mean_nees, 2.0);
  ASSERT_TRUE(p.recovery.has_value());
  EXPECT_EQ(p.recovery->position_m, 0.25);
  EXPECT_EQ(p.recovery->within_s, 4.0);
  EXPECT_EQ(p.recovery->lost_within_s, PassThresholds::Recovery{}.lost_within_s);  // its default
  EXPECT_FALSE(parse_scenario(R"(world: campus
duration_s: 30
ego: {route: {road: loop, lane: right}}
)",
                              "none.yaml")
                   .pass.recovery.has_value());
  // `score --threshold` goes through the same reader, over the scenario's values.
  const PassThresholds q = parse_pass_assignment("recovery={lost_within_s: 0.5}", "--threshold", p);
  EXPECT_EQ(q.recovery->position_m, 0.25);
  EXPECT_EQ(q.recovery->lost_within_s, 0.5);
  EXPECT_EQ(parse_pass_assignment("alert_limit_longitudinal_m=1.4", "--threshold", {}).alert_limit_longitudinal_m, 1.4);

  auto error = [&](const std::string& from, const std::string& to) {
    std::string bad = scenario;
    bad.replace(bad.find(from), from.size(), to);
    try {
      parse_scenario(bad, "bad.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("max_misleading_fraction: 0.001", "max_misleading_fraction: 2"),
            "bad.yaml:5:28: max_misleading_fraction = 2 is out of range [0, 1]");
  EXPECT_EQ(error("within_s: 4", "within_s: soon").rfind("bad.yaml:10:42: within_s must be a finite number", 0), 0u);
  EXPECT_EQ(error("within_s: 4", "within: 4").rfind("bad.yaml:10:32: unknown key 'within'", 0), 0u);
  EXPECT_EQ(error("min_mean_nees: 0.5", "min_mean_nees: 3").rfind("bad.yaml:8:18: min_mean_nees is above", 0), 0u);
  EXPECT_EQ(error("alert_limit_lateral_m: 0.5", "alert_limit_lateral_m: -1").rfind("bad.yaml:7:26: ", 0), 0u);
}

std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("lidarloop_test_integrity_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(IntegrityFiles, ErrorsCsvAppendsTheColumnsAndMetricsJsonHoldsTheFigures) {
  const std::vector<FaultEvent> events = {{0, "start"}, {10'000 * kMs, "kidnap"}};
  const auto est = kidnapped();
  PassThresholds t;
  t.recovery = PassThresholds::Recovery{};
  const ScoredRun run = score(straight_truth(20), est, straight_route(), t, "m", "s", events);
  const std::string path = temp_path("errors.csv");
  write_errors_csv(path, run, est);
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header,
            "t_s,lateral_m,longitudinal_m,heading_deg,position_m,est_x_m,est_y_m,est_yaw_rad,truth_x_m,truth_y_m,"
            "truth_yaw_rad,status,latency_ms,sigma_x_m,sigma_y_m,sigma_yaw_deg,sigma_lateral_m,sigma_longitudinal_m,"
            "nees_lateral,nees_longitudinal,nees_heading,protection_lateral_m,protection_longitudinal_m,lost,"
            "misleading,awaiting_alert");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 201u);
  // 10.1 s: 4 m left, sigma 0.1 m: NEES 1600 lateral; bounds 0.2 m; not yet lost: misleading, awaiting
  // the alert raised at 10.4 s.
  EXPECT_NE(lines[101].find(",0.1,0.1,1600,0,0,0.2,0.2,0,1,1"), std::string::npos) << lines[101];
  // 10.5 s: lost, so not misleading.
  EXPECT_NE(lines[105].find(",0.2,0.2,1,0,0"), std::string::npos) << lines[105];

  const auto j = nlohmann::json::parse(metrics_json(run.metrics));
  EXPECT_EQ(j["recovery_frames"], 31);
  EXPECT_EQ(j["integrity"]["misleading_frames"], 0);
  EXPECT_EQ(j["integrity"]["misleading_awaiting_alert"], 4);
  EXPECT_EQ(j["integrity"]["frames_awaiting_alert"], 4);
  EXPECT_EQ(j["recovery"][1]["event"], "kidnap");
  EXPECT_NEAR(j["recovery"][1]["converged_after_s"].get<double>(), 1.5, 1e-9);
  EXPECT_TRUE(j["recovery"][0]["lost_raised_after_s"].is_null());
  EXPECT_DOUBLE_EQ(j["consistency"]["mean_nees_lateral"].get<double>(), 0.0);  // the 4 m frames await the alert
  EXPECT_EQ(j["thresholds"]["alert_limit_lateral_m"], kLocalStreetAlertLimit_m);
  EXPECT_EQ(j["thresholds"]["recovery"]["within_s"], 3.0);
}

// Pixels of exactly `colour` (BGR): the band's fill is drawn without blending inside.
int count_colour(const cv::Mat& image, const cv::Vec3b& colour) {
  int n = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) n += image.at<cv::Vec3b>(r, c) == colour;
  return n;
}

// Warm pixels (red well above blue): the lost tint on white, and the protection bounds.
int count_warm(const cv::Mat& image) {
  constexpr int kWarm = 40;
  int n = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      const cv::Vec3b p = image.at<cv::Vec3b>(r, c);
      n += int(p[2]) - int(p[0]) >= kWarm;
    }
  return n;
}

TEST(IntegrityFiles, ErrorPlotShadesLostStretchesAndTheSigmaBand) {
  const std::vector<FaultEvent> events = {{0, "start"}, {10'000 * kMs, "kidnap"}};
  const ScoredRun run = score(straight_truth(20), kidnapped(), straight_route(), {}, "m", "s", events);
  const std::string png = temp_path("errors.png");
  write_error_plot(png, run.errors, events);
  const cv::Mat image = cv::imread(png);
  ASSERT_EQ(image.cols, 1200);
  ASSERT_EQ(image.rows, 900);
  EXPECT_GT(count_colour(image, cv::Vec3b(245, 228, 210)), 1000);  // the band
  // The same bounds and band without `lost` frames: the 1.6 s lost stretch of 20 s is what tints
  // thousands of pixels more.
  const auto calm = estimates(
      20, [](double) { return 0.05; }, [](double) { return false; });
  const std::string calm_png = temp_path("errors_calm.png");
  write_error_plot(calm_png, score(straight_truth(20), calm, straight_route(), {}, "m", "s").errors, events);
  EXPECT_GT(count_warm(image), count_warm(cv::imread(calm_png)) + 5000);
  // An absurd claim (a bound and a sigma of 1e12 m) is drawn clipped at the panel, not dash by dash.
  auto absurd = run.errors;
  absurd[50].protection_lateral_m = absurd[50].sigma_lateral_m = 1e12;
  write_error_plot(calm_png, absurd, events);
  EXPECT_EQ(cv::imread(calm_png).cols, 1200);
}

}  // namespace
}  // namespace lidarloop
