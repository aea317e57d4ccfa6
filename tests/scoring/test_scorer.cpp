// The scorer, the result files and the plots, on inputs whose errors are known by construction.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "scoring/error_plots.hpp"
#include "scoring/result_files.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kEps = 1e-12;
constexpr int64_t kMs = 1'000'000;

// Every error threshold at `value` (lane keeping and settling unset).
PassThresholds thresholds_at(double value) {
  PassThresholds t;
  t.lateral_rmse_m = t.longitudinal_rmse_m = t.heading_rmse_deg = t.max_position_error_m = value;
  return t;
}

// The lane the straight truth below drives along, `lateral` m to its left: open, and longer than any
// drive here.
Path straight_route(double lateral = 0) {
  constexpr double kLength = 1000;  // m
  return make_path({{0, lateral}, {kLength, lateral}}, false);
}

// A straight drive east at 10 m/s, 100 Hz, for `seconds`.
std::vector<TruthPose> straight_truth(double seconds) {
  std::vector<TruthPose> truth;
  for (int64_t t = 0; t <= int64_t(seconds * 1000) * kMs; t += 10 * kMs)
    truth.push_back({t, {10.0 * double(t) / 1e9, 0, 0}});
  return truth;
}

// Estimates at 10 Hz offset from the straight truth by (longitudinal, lateral, heading).
std::vector<EstimateRecord> offset_estimates(double seconds, double lon, double lat, double yaw,
                                             double latency_ms = 5) {
  std::vector<EstimateRecord> out;
  for (int64_t t = 0; t <= int64_t(seconds * 1000) * kMs; t += 100 * kMs) {
    EstimateRecord e;
    e.stamp_ns = t;
    e.pose = {10.0 * double(t) / 1e9 + lon, lat, yaw};
    e.covariance = Eigen::Vector3d(0.04, 0.09, 0.0001).asDiagonal();
    e.status = "tracking";
    e.latency_ms = latency_ms;
    out.push_back(e);
  }
  return out;
}

std::string temp_path(const std::string& name) {
  // Per process: CTest runs test cases as parallel processes.
  const auto dir = std::filesystem::temp_directory_path() / ("lidarloop_test_scorer_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

std::string read_all(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* const kUnwritableDir = "/nonexistent_lidarloop_dir";

TEST(RatedFrames, SettlingFromTheFirstEstimateAndRecoveringAfterAFaultButNotTheStart) {
  // What score() keeps out of its RMSEs and maxima, and the worst-frame picture with it.
  PassThresholds t;
  t.settle_s = 2.0;
  const int64_t s = kNsPerS;
  EXPECT_TRUE(settling(2 * s + s / 2, s, t));  // 1.5 s after the first estimate
  EXPECT_FALSE(settling(3 * s, s, t));
  const std::vector<FaultEvent> events = {{0, "start"}, {8 * s, "kidnap"}};
  EXPECT_FALSE(recovering(8 * s + s / 2, t, events));  // no recovery criteria: every frame is rated
  t.recovery = PassThresholds::Recovery{};             // within 3 s
  EXPECT_TRUE(recovering(8 * s + s / 2, t, events));
  EXPECT_TRUE(recovering(11 * s, t, events));
  EXPECT_FALSE(recovering(11 * s + 1, t, events));
  EXPECT_FALSE(recovering(7 * s, t, events));
  EXPECT_FALSE(recovering(s, t, events));  // the start is settle_s's
}

TEST(FrameError, DisplacementAlongHeadingIsLongitudinal) {
  for (double yaw : {0.0, 0.7, kPi / 2, 2.5, -kPi / 2, -3.0}) {
    const Pose2d truth{3, -4, yaw};
    const Pose2d ahead{3 + std::cos(yaw), -4 + std::sin(yaw), yaw};
    const FrameError e = frame_error(truth, ahead);
    EXPECT_NEAR(e.longitudinal_m, 1, kEps) << yaw;
    EXPECT_NEAR(e.lateral_m, 0, kEps) << yaw;
    EXPECT_NEAR(e.heading_rad, 0, kEps) << yaw;
    EXPECT_NEAR(e.position_m, 1, kEps) << yaw;
  }
}

TEST(FrameError, LeftDisplacementIsPositiveLateral) {
  for (double yaw : {0.0, 1.0, -2.0, kPi}) {
    const Pose2d truth{1, 2, yaw};
    const Pose2d left{1 - 0.5 * std::sin(yaw), 2 + 0.5 * std::cos(yaw), yaw};
    const FrameError e = frame_error(truth, left);
    EXPECT_NEAR(e.lateral_m, 0.5, kEps) << yaw;
    EXPECT_NEAR(e.longitudinal_m, 0, kEps) << yaw;
  }
}

TEST(FrameError, HeadingWrapsAcrossPi) {
  const FrameError e = frame_error({0, 0, kPi - 0.1}, {0, 0, -kPi + 0.1});
  EXPECT_NEAR(e.heading_rad, 0.2, kEps);
  EXPECT_NEAR(frame_error({0, 0, -kPi + 0.05}, {0, 0, kPi - 0.05}).heading_rad, -0.1, kEps);
  EXPECT_NEAR(frame_error({0, 0, 0}, {0, 0, 4 * kPi + 0.3}).heading_rad, 0.3, kEps);
}

TEST(TruthAt, InterpolatesMidwayAndAtSamples) {
  const std::vector<TruthPose> truth = {{0, {0, 0, 0.1}}, {10 * kMs, {1, 2, 0.3}}, {20 * kMs, {3, 2, 0.3}}};
  const Pose2d mid = truth_at(truth, 5 * kMs);
  EXPECT_NEAR(mid.x, 0.5, kEps);
  EXPECT_NEAR(mid.y, 1.0, kEps);
  EXPECT_NEAR(mid.yaw, 0.2, kEps);
  EXPECT_NEAR(truth_at(truth, 10 * kMs).x, 1, kEps);
  EXPECT_NEAR(truth_at(truth, 20 * kMs).x, 3, kEps);
  EXPECT_NEAR(truth_at(truth, 0).yaw, 0.1, kEps);
}

TEST(TruthAt, InterpolatesYawAcrossTheWrap) {
  const std::vector<TruthPose> truth = {{0, {0, 0, kPi - 0.1}}, {10 * kMs, {0, 0, -kPi + 0.1}}};
  const Pose2d mid = truth_at(truth, 5 * kMs);
  EXPECT_NEAR(std::abs(mid.yaw), kPi, 1e-9);  // through pi, not through 0
  const Pose2d quarter = truth_at(truth, 2'500'000);
  EXPECT_NEAR(quarter.yaw, kPi - 0.05, 1e-9);
}

TEST(TruthAt, ThrowsOutsideRangeOrEmpty) {
  const std::vector<TruthPose> truth = {{10, {}}, {20, {}}};
  EXPECT_THROW(truth_at(truth, 9), std::out_of_range);
  EXPECT_THROW(truth_at(truth, 21), std::out_of_range);
  EXPECT_THROW(truth_at({}, 0), std::out_of_range);
}

TEST(Score, RmseOfConstantKnownErrors) {
  const ScoredRun run =
      score(straight_truth(5), offset_estimates(5, 0.3, -0.2, 0.01), straight_route(), {}, "test", "straight");
  const Metrics& m = run.metrics;
  EXPECT_EQ(m.frames, 51u);
  EXPECT_EQ(run.errors.size(), 51u);
  EXPECT_NEAR(m.longitudinal_rmse_m, 0.3, 1e-9);
  EXPECT_NEAR(m.lateral_rmse_m, 0.2, 1e-9);
  EXPECT_NEAR(m.heading_rmse_deg, 0.01 * 180 / kPi, 1e-9);
  EXPECT_NEAR(m.max_position_error_m, std::hypot(0.3, 0.2), 1e-9);
  EXPECT_NEAR(m.max_lateral_m, 0.2, 1e-9);
  EXPECT_NEAR(run.errors.front().lateral_m, -0.2, 1e-9);  // to the right: negative
  EXPECT_TRUE(m.pass);                                    // no thresholds set
  EXPECT_TRUE(m.failures.empty());
}

TEST(Score, RmseOfAlternatingErrors) {
  std::vector<EstimateRecord> est = offset_estimates(1, 0, 0, 0);
  for (size_t i = 0; i < est.size(); ++i) est[i].pose.y = (i % 2 ? 0.3 : -0.3);
  EXPECT_NEAR(score(straight_truth(1), est, straight_route(), {}, "m", "s").metrics.lateral_rmse_m, 0.3, 1e-9);
  EXPECT_NEAR(rmse({3, 4}), std::sqrt(12.5), kEps);
  EXPECT_TRUE(std::isnan(rmse({})));
}

TEST(Score, NearestRankPercentiles) {
  const std::vector<double> v = {15, 20, 35, 40, 50};  // the textbook nearest-rank example
  EXPECT_EQ(percentile_nearest_rank(v, 5), 15);
  EXPECT_EQ(percentile_nearest_rank(v, 30), 20);
  EXPECT_EQ(percentile_nearest_rank(v, 40), 20);
  EXPECT_EQ(percentile_nearest_rank(v, 50), 35);
  EXPECT_EQ(percentile_nearest_rank(v, 100), 50);
  EXPECT_EQ(percentile_nearest_rank(v, 0), 15);
  std::vector<double> hundred;
  for (int i = 100; i >= 1; --i) hundred.push_back(i);  // unsorted input
  EXPECT_EQ(percentile_nearest_rank(hundred, 99), 99);
  EXPECT_EQ(percentile_nearest_rank(hundred, 50), 50);
  EXPECT_TRUE(std::isnan(percentile_nearest_rank({}, 50)));

  std::vector<EstimateRecord> est = offset_estimates(9.9, 0, 0, 0);  // 100 frames
  ASSERT_EQ(est.size(), 100u);
  for (size_t i = 0; i < est.size(); ++i) est[i].latency_ms = double(i + 1);
  const Metrics m = score(straight_truth(10), est, straight_route(), {}, "m", "s").metrics;
  EXPECT_EQ(m.latency_p50_ms, 50);
  EXPECT_EQ(m.latency_p99_ms, 99);
  EXPECT_EQ(m.latency_max_ms, 100);
  EXPECT_TRUE(std::isnan(m.latency_first_scan_ms));

  // The first scan's latency (a program's start-up: 435 ms) is reported apart, not as the worst.
  est.front().first_scan = true;
  est.front().latency_ms = 435;
  const Metrics apart = score(straight_truth(10), est, straight_route(), {}, "m", "s").metrics;
  EXPECT_EQ(apart.latency_first_scan_ms, 435);
  EXPECT_EQ(apart.latency_max_ms, 100);
  EXPECT_EQ(apart.latency_p50_ms, 51);  // of 2..100
}

TEST(Score, EachThresholdTripsOnItsOwn) {
  const auto truth = straight_truth(3);
  const auto est = offset_estimates(3, 0.3, 0.2, 0.01);  // 0.2 m lateral, 0.3 m long, 0.573 deg, 0.361 m
  const PassThresholds loose = thresholds_at(1.0);
  EXPECT_TRUE(score(truth, est, straight_route(), loose, "m", "s").metrics.pass);

  auto trip = [&](PassThresholds t, const std::string& expected) {
    const Metrics m = score(truth, est, straight_route(), t, "m", "s").metrics;
    EXPECT_FALSE(m.pass) << expected;
    ASSERT_EQ(m.failures.size(), 1u) << expected;
    EXPECT_EQ(m.failures[0], expected);
  };
  PassThresholds t = loose;
  t.lateral_rmse_m = 0.1;
  trip(t, "lateral RMSE 0.200 m > 0.100 m");
  t = loose;
  t.longitudinal_rmse_m = 0.25;
  trip(t, "longitudinal RMSE 0.300 m > 0.250 m");
  t = loose;
  t.heading_rmse_deg = 0.5;
  trip(t, "heading RMSE 0.573 deg > 0.500 deg");
  t = loose;
  t.max_position_error_m = 0.3;
  trip(t, "max position error 0.361 m > 0.300 m");
}

TEST(Score, NoEstimatesFails) {
  const Metrics m = score(straight_truth(1), {}, straight_route(), {}, "m", "s").metrics;
  EXPECT_EQ(m.frames, 0u);
  EXPECT_FALSE(m.pass);
  ASSERT_EQ(m.failures.size(), 1u);
  EXPECT_EQ(m.failures[0], "no estimates");
}

TEST(Score, EstimatesOutsideTruthAreCountedNotScored) {
  auto est = offset_estimates(2, 0.1, 0, 0);
  const Metrics m = score(straight_truth(1), est, straight_route(), {}, "m", "s").metrics;
  EXPECT_EQ(m.frames, 11u);
  EXPECT_EQ(m.unscored_frames, 10u);
  EXPECT_TRUE(m.pass);
  EXPECT_FALSE(score({}, est, straight_route(), {}, "m", "s").metrics.pass);
}

TEST(Score, DivergedEstimateFails) {
  auto est = offset_estimates(1, 0, 0, 0);
  est[3].pose.x = std::nan("");
  const Metrics m = score(straight_truth(1), est, straight_route(), thresholds_at(1.0), "m", "s").metrics;
  EXPECT_FALSE(m.pass);
}

TEST(CurbOcclusion, HiddenOverInSightSummedOverScansAndTheWorstScan) {
  // Scan 2 has 30 of 40 in sight hidden (0.75, the worst); scan 3 has no sample in range and counts
  // for neither figure; what the static world hid is in neither count.
  const std::vector<CurbVisibility> scans = {{0, 90, 10, 5}, {100 * kMs, 10, 30, 7}, {200 * kMs, 0, 0, 3}};
  const CurbOcclusion o = curb_occlusion(scans);
  EXPECT_DOUBLE_EQ(o.hidden_fraction, 40.0 / 140.0);
  EXPECT_DOUBLE_EQ(o.hidden_fraction_max, 0.75);
  // No traffic in the way: exactly 0, not NaN.
  const CurbOcclusion clear = curb_occlusion({{0, 50, 0, 0}, {100 * kMs, 60, 0, 2}});
  EXPECT_EQ(clear.hidden_fraction, 0.0);
  EXPECT_EQ(clear.hidden_fraction_max, 0.0);
  // Nothing in range, or nothing measured: no fraction at all.
  EXPECT_TRUE(std::isnan(curb_occlusion({{0, 0, 0, 4}}).hidden_fraction));
  EXPECT_TRUE(std::isnan(curb_occlusion({}).hidden_fraction_max));
}

TEST(CurbOcclusion, ScoreCarriesItIntoTheMetricsAndTheirJson) {
  const Metrics m = score(straight_truth(1), offset_estimates(1, 0, 0, 0), straight_route(), {}, "m", "s", {},
                          {{0, 30, 10, 0}, {100 * kMs, 20, 40, 0}})
                        .metrics;
  EXPECT_DOUBLE_EQ(m.curb_hidden_fraction, 0.5);
  EXPECT_DOUBLE_EQ(m.curb_hidden_fraction_max, 40.0 / 60.0);
  const auto j = nlohmann::json::parse(metrics_json(m));
  EXPECT_DOUBLE_EQ(j["curb_hidden_fraction"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["curb_hidden_fraction_max"].get<double>(), 40.0 / 60.0);
  EXPECT_EQ(curb_occlusion_text(m), "the traffic hid 50.0% of the curb samples in range (worst scan 66.7%)");
  const auto unknown = nlohmann::json::parse(metrics_json(score({}, {}, straight_route(), {}, "gps", "s").metrics));
  EXPECT_TRUE(unknown["curb_hidden_fraction"].is_null());
  EXPECT_TRUE(unknown["curb_hidden_fraction_max"].is_null());
}

TEST(ResultFiles, MetricsJsonRoundTrip) {
  PassThresholds t;
  t.lateral_rmse_m = 0.1;
  t.heading_rmse_deg = 0.3;
  const Metrics m =
      score(straight_truth(2), offset_estimates(2, 0.3, 0.2, 0.01, 7.5), straight_route(), t, "proposed", "dyn")
          .metrics;
  const std::string path = temp_path("metrics.json");
  write_metrics_json(path, m);
  const auto j = nlohmann::json::parse(read_all(path));
  EXPECT_EQ(j["method"], "proposed");
  EXPECT_EQ(j["scenario"], "dyn");
  EXPECT_EQ(j["frames"], m.frames);
  EXPECT_DOUBLE_EQ(j["lateral_rmse_m"].get<double>(), m.lateral_rmse_m);
  EXPECT_DOUBLE_EQ(j["longitudinal_rmse_m"].get<double>(), m.longitudinal_rmse_m);
  EXPECT_DOUBLE_EQ(j["heading_rmse_deg"].get<double>(), m.heading_rmse_deg);
  EXPECT_DOUBLE_EQ(j["max_position_error_m"].get<double>(), m.max_position_error_m);
  EXPECT_DOUBLE_EQ(j["latency_p50_ms"].get<double>(), 7.5);
  EXPECT_DOUBLE_EQ(j["latency_p99_ms"].get<double>(), 7.5);
  EXPECT_EQ(j["pass"], false);
  EXPECT_DOUBLE_EQ(j["thresholds"]["lateral_rmse_m"].get<double>(), 0.1);
  EXPECT_TRUE(j["thresholds"]["longitudinal_rmse_m"].is_null());
  ASSERT_EQ(j["failures"].size(), 2u);
  EXPECT_EQ(j["failures"][0], m.failures[0]);

  // Undefined values (no frames, no truth) are null, not an invalid NaN token.
  const auto empty = nlohmann::json::parse(metrics_json(score({}, {}, straight_route(), {}, "gps", "s").metrics));
  EXPECT_TRUE(empty["lateral_rmse_m"].is_null());
  EXPECT_TRUE(empty["max_lane_offset_m"].is_null());
}

TEST(ResultFiles, TumLineFormat) {
  EXPECT_EQ(tum_line(1'500'000'000, {1.25, -2.5, 0}), "1.500000000 1.25 -2.5 0 0 0 0 1");
  std::istringstream in(tum_line(123'456'789'012, {1234.56789012, 0.1, kPi / 2}));
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  ASSERT_EQ(v.size(), 8u);
  EXPECT_DOUBLE_EQ(v[0], 123.456789012);
  EXPECT_EQ(v[1], 1234.56789012);  // exact: the shortest text that reads back as the same double
  EXPECT_EQ(v[3], 0);
  EXPECT_EQ(v[6], std::sin(kPi / 4));
  EXPECT_EQ(v[7], std::cos(kPi / 4));

  const std::string path = temp_path("truth.tum");
  write_tum(path, straight_truth(1));
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  EXPECT_EQ(line[0], '#');
  size_t lines = 0;
  while (std::getline(file, line)) ++lines;
  EXPECT_EQ(lines, 101u);
  write_tum(temp_path("estimate.tum"), offset_estimates(1, 0, 0, 0));
}

TEST(ResultFiles, JunitHasFailureExactlyWhenFailing) {
  PassThresholds t;
  t.lateral_rmse_m = 0.1;
  const auto truth = straight_truth(1);
  const Metrics good =
      score(truth, offset_estimates(1, 0, 0.05, 0), straight_route(), t, "proposed", "a<&>\"b").metrics;
  const Metrics bad = score(truth, offset_estimates(1, 0, 0.5, 0), straight_route(), t, "icp", "a<&>\"b").metrics;
  const Metrics other = score(truth, offset_estimates(1, 0, 0.05, 0), straight_route(), t, "gps", "static").metrics;
  const std::string pass_xml = junit_xml({good, other});
  EXPECT_EQ(pass_xml.find("<failure"), std::string::npos);
  const std::string xml = junit_xml({good, bad, other});
  EXPECT_NE(xml.find("<failure message=\"lateral RMSE 0.500 m &gt; 0.100 m\""), std::string::npos) << xml;
  EXPECT_EQ(xml.find("<failure"), xml.rfind("<failure"));  // only one
  EXPECT_NE(xml.find("<testsuite name=\"a&lt;&amp;&gt;&quot;b\" tests=\"2\" failures=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<testsuite name=\"static\" tests=\"1\" failures=\"0\""), std::string::npos);
  EXPECT_EQ(xml.find("a<&>"), std::string::npos);
  write_junit(temp_path("junit.xml"), {good, bad});
}

TEST(ResultFiles, ComparisonTableAndCsv) {
  const auto truth = straight_truth(1);
  PassThresholds t;
  t.lateral_rmse_m = 0.1;
  const std::vector<Metrics> runs = {
      score(truth, offset_estimates(1, 0.1, 0.05, 0), straight_route(), t, "proposed", "s").metrics,
      score(truth, offset_estimates(1, 2.5, 0.5, 0), straight_route(), t, "icp", "s").metrics};
  const std::string md = comparison_markdown(runs);
  EXPECT_NE(
      md.find("| method | lateral RMSE m | longitudinal RMSE m | heading RMSE deg | max error m | latency p50 ms"),
      std::string::npos);
  EXPECT_NE(md.find("| proposed | 0.050 | 0.100 | 0.000 | 0.112 | 5.00 | 100.0% | pass |"), std::string::npos) << md;
  EXPECT_NE(md.find("| icp | 0.500 | 2.500 |"), std::string::npos) << md;
  EXPECT_NE(md.find("FAIL"), std::string::npos);
  const std::string path = temp_path("compare.csv");
  write_comparison_csv(path, runs);
  const std::string csv = read_all(path);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "scenario,method,frames,lateral_rmse_m,longitudinal_rmse_m,heading_rmse_deg,max_position_error_m,"
            "latency_p50_ms,latency_p99_ms,pass");
  EXPECT_NE(csv.find("s,icp,11,0.5,2.5,0,"), std::string::npos) << csv;
}

TEST(ResultFiles, ErrorsCsvHasOneLinePerScoredFrame) {
  const auto est = offset_estimates(2, 0.3, 0.2, 0);
  const ScoredRun run = score(straight_truth(1), est, straight_route(), {}, "m", "s");
  const std::string path = temp_path("errors.csv");
  write_errors_csv(path, run, est);
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.substr(0, 46), "t_s,lateral_m,longitudinal_m,heading_deg,posit");
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), run.errors.size());
  EXPECT_EQ(lines[1].substr(0, lines[1].find(",tracking")), "0.100000000,0.2,0.3,0,0.360555128,1.3,0.2,0,1,0,0");
  EXPECT_NE(lines[1].find(",tracking,5,0.2,0.3,"), std::string::npos) << lines[1];
}

TEST(ResultFiles, UnwritablePathThrowsNamingIt) {
  const std::string dir = kUnwritableDir;
  const Metrics m = score(straight_truth(1), offset_estimates(1, 0, 0, 0), straight_route(), {}, "m", "s").metrics;
  auto expect_names = [&](const std::function<void(const std::string&)>& write, const std::string& name) {
    const std::string path = dir + "/" + name;
    try {
      write(path);
      ADD_FAILURE() << name << " did not throw";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expect_names([&](const std::string& p) { write_metrics_json(p, m); }, "metrics.json");
  expect_names([&](const std::string& p) { write_errors_csv(p, {}, {}); }, "errors.csv");
  expect_names([&](const std::string& p) { write_tum(p, straight_truth(1)); }, "truth.tum");
  expect_names([&](const std::string& p) { write_junit(p, {m}); }, "junit.xml");
  expect_names([&](const std::string& p) { write_comparison_csv(p, {m}); }, "compare.csv");
  expect_names([&](const std::string& p) { write_error_plot(p, {}); }, "errors.png");
  expect_names([&](const std::string& p) { write_trajectory_plot(p, {}, {}, {}); }, "trajectory.png");
}

TEST(ErrorPlots, WritePngsOfTheRequestedSize) {
  // A lane change and back, with a growing longitudinal error, on an S-curve.
  std::vector<TruthPose> truth;
  for (int64_t t = 0; t <= 20'000 * kMs; t += 10 * kMs) {
    const double s = double(t) / 1e9;
    truth.push_back({t, {10 * s, 20 * std::sin(s / 4), std::atan2(5 * std::cos(s / 4), 10.0)}});
  }
  std::vector<EstimateRecord> est;
  for (int64_t t = 0; t <= 20'000 * kMs; t += 100 * kMs) {
    const double s = double(t) / 1e9;
    const Pose2d p = truth_at(truth, t);
    EstimateRecord e;
    e.stamp_ns = t;
    e.pose = {p.x + 0.02 * s, p.y + 0.3 * std::sin(s), p.yaw + 0.01 * std::cos(s)};
    est.push_back(e);
  }
  const ScoredRun run = score(truth, est, straight_route(), {}, "m", "s");
  const Polyline2d curb = {{0, -5}, {100, -5}, {200, -5}};

  const std::string errors_png = temp_path("errors.png"), trajectory_png = temp_path("trajectory.png");
  write_error_plot(errors_png, run.errors);
  write_trajectory_plot(trajectory_png, truth, est, run.errors, {curb});
  for (const auto& path : {errors_png, trajectory_png}) {
    EXPECT_GT(std::filesystem::file_size(path), 0u);
    const cv::Mat image = cv::imread(path);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_EQ(image.cols, 1200);
    EXPECT_EQ(image.rows, 900);
  }
  // Other sizes, and degenerate inputs draw rather than crash.
  write_error_plot(errors_png, {}, {}, {800, 600});
  EXPECT_EQ(cv::imread(errors_png).cols, 800);
  write_trajectory_plot(trajectory_png, {}, {}, {}, {}, {640, 480});
  EXPECT_EQ(cv::imread(trajectory_png).rows, 480);
  EXPECT_THROW(write_error_plot(errors_png, run.errors, {}, {100, 100}), InputError);
}

TEST(Score, SettlingFramesAreNotScoredAndLaneKeepingIsChecked) {
  const auto truth = straight_truth(3);
  auto est = offset_estimates(3, 0.0, 0.0, 0.0);
  est.front().pose.y += 5.0;  // the first fix, metres off
  PassThresholds t;
  t.max_position_error_m = 1.0;
  EXPECT_FALSE(score(truth, est, straight_route(), t, "m", "s").metrics.pass);
  t.settle_s = 1e-9 * double(est[1].stamp_ns - est[0].stamp_ns) / 2;  // only the first frame settles
  ScoredRun run = score(truth, est, straight_route(), t, "m", "s");
  EXPECT_TRUE(run.metrics.pass);
  EXPECT_EQ(run.metrics.settling_frames, 1u);
  EXPECT_NEAR(run.metrics.max_lane_offset_m, 0, kEps);  // the truth drives on the route

  // The truth 0.4 m, then 0.6 m, to the right of its lane's centre.
  t.max_lane_offset_m = 0.5;
  run = score(truth, est, straight_route(0.4), t, "m", "s");
  EXPECT_TRUE(run.metrics.pass);
  EXPECT_NEAR(run.metrics.max_lane_offset_m, 0.4, kEps);
  run = score(truth, est, straight_route(0.6), t, "m", "s");
  EXPECT_FALSE(run.metrics.pass);
  EXPECT_NEAR(run.metrics.max_lane_offset_m, 0.6, kEps);
  ASSERT_EQ(run.metrics.failures.size(), 1u);
  EXPECT_EQ(run.metrics.failures[0], "lane offset 0.600 m > 0.500 m");
}

// ---- Lane keeping on a circle: known truth, offset a constant distance from the route ----

constexpr double kCircleRadius = 50;        // m
constexpr double kCircleVertexStep = 0.25;  // degrees between the route's vertices
// A point at constant distance from the circle is within R (1 - cos(step / 2)) = 0.12 mm of that
// distance from the polyline through its vertices: the tolerance says the route was followed.
constexpr double kLaneTolerance = 1e-3;   // m
constexpr double kLaneSpeed = 10;         // m/s
constexpr int64_t kTruthStep = 10 * kMs;  // 100 Hz

// The circle about the origin, counter-clockwise, from (R, 0); `degrees` of it (360: closed).
Path circle_route(double degrees) {
  Polyline2d points;
  for (double a = 0; a <= degrees + 1e-9; a += kCircleVertexStep)
    points.push_back(kCircleRadius * Eigen::Vector2d(std::cos(a * kDeg), std::sin(a * kDeg)));
  return make_path(points, degrees >= 360);
}

// Driving the circle counter-clockwise at kLaneSpeed from angle `start_rad` for `seconds`, `left` m to
// the left of it (towards the centre), heading along it.
std::vector<TruthPose> circle_truth(double start_rad, double seconds, double left) {
  std::vector<TruthPose> truth;
  for (int64_t t = 0; t < int64_t(seconds * double(kNsPerS)); t += kTruthStep) {
    const double a = start_rad + kLaneSpeed * ns_to_s(t) / kCircleRadius;
    const double r = kCircleRadius - left;
    truth.push_back({t, {r * std::cos(a), r * std::sin(a), wrap_angle(a + kPi / 2)}});
  }
  return truth;
}

// A learnt mount yaw against the drawn 0.2 deg: 0.05, 0.18, 0.25, 0.19, 0.21 deg at 0-4 s. Within
// 0.03 deg from 3 s on (the 0.18 at 1 s fell out again at 2 s); the last is 0.01 off. Estimates without
// one (another localizer) give no figures.
TEST(MountYawMetrics, TheLastEstimateAndWhenItStayedWithinTolerance) {
  std::vector<EstimateRecord> estimates;
  for (double yaw : {0.05, 0.18, 0.25, 0.19, 0.21}) {
    EstimateRecord e;
    e.stamp_ns = int64_t(estimates.size()) * kNsPerS;
    e.mount_yaw_deg = yaw;
    e.mount_yaw_sigma_deg = 0.1 / double(estimates.size() + 1);
    estimates.push_back(e);
  }
  const std::optional<MountYawMetrics> m = mount_yaw_metrics(estimates, 0.2, 0.03);
  ASSERT_TRUE(m.has_value());
  EXPECT_DOUBLE_EQ(m->learnt_deg, 0.21);
  EXPECT_DOUBLE_EQ(m->sigma_deg, 0.02);
  EXPECT_NEAR(m->error_deg, 0.01, 1e-12);
  ASSERT_TRUE(m->settled_s.has_value());
  EXPECT_DOUBLE_EQ(*m->settled_s, 3.0);
  estimates.back().mount_yaw_deg = 0.3;  // out again at the end: not settled
  EXPECT_FALSE(mount_yaw_metrics(estimates, 0.2, 0.03)->settled_s.has_value());
  for (EstimateRecord& e : estimates) e.mount_yaw_deg = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(mount_yaw_metrics(estimates, 0.2, 0.03).has_value());
}

TEST(LaneOffsets, FollowTheCarRoundAClosedRouteLapAfterLap) {
  constexpr int kLaps = 4;
  constexpr double kLeft = 0.35;               // m, the truth's known offset from its lane's centre
  constexpr double kStartRad = 0.3 * 2 * kPi;  // the first seam crossing comes mid-lap, as in a scenario
  const Path route = circle_route(360);
  ASSERT_TRUE(route.closed);
  const double lap_s = 2 * kPi * kCircleRadius / kLaneSpeed;
  const std::vector<TruthPose> truth = circle_truth(kStartRad, kLaps * lap_s, kLeft);

  const std::vector<double> offsets = lane_offsets(truth, route);
  ASSERT_EQ(offsets.size(), truth.size());
  std::vector<double> worst_in_lap(kLaps, 0.0);  // the largest departure from kLeft, per lap
  std::vector<size_t> samples_in_lap(kLaps, 0);
  for (size_t i = 0; i < truth.size(); ++i) {
    const size_t lap = size_t(ns_to_s(truth[i].stamp_ns) / lap_s);
    worst_in_lap.at(lap) = std::max(worst_in_lap[lap], std::abs(offsets[i] - kLeft));
    ++samples_in_lap[lap];
  }
  for (int lap = 0; lap < kLaps; ++lap) {
    EXPECT_GT(samples_in_lap[lap], 0u) << "lap " << lap + 1;
    EXPECT_LT(worst_in_lap[lap], kLaneTolerance) << "lap " << lap + 1;
  }

  PassThresholds t;
  t.max_lane_offset_m = 0.5;
  const Metrics m = score(truth, {}, route, t, "m", "circle").metrics;
  EXPECT_NEAR(m.max_lane_offset_m, kLeft, kLaneTolerance);
  EXPECT_EQ(m.failures, std::vector<std::string>{"no estimates"});  // and nothing about the lane
}

// A route that passes its start again later (two laps of a spiral, as a scenario's laps joined by
// U-turns at a map's edge come back through the start): the car on its first lap, 0.15 m inside it, is
// nearer to the second lap (0.05 m) at the start. Its offset is to the first lap, all the way round.
TEST(LaneOffsets, AnOpenRouteThatComesBackThroughItsStartIsFollowedFromItsFirstPass) {
  constexpr double kInside = 0.15, kInward = 0.2;  // m; kInward: the second lap's radius is this much less
  Polyline2d spiral;
  for (double deg = 0; deg <= 720 + 1e-9; deg += kCircleVertexStep) {
    const double a = deg * kDeg, r = kCircleRadius - kInward * a / (2 * kPi);
    spiral.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  const Path route = make_path(spiral, false);
  std::vector<TruthPose> truth;
  const double lap_s = 2 * kPi * kCircleRadius / kLaneSpeed;
  for (int64_t t = 0; t < int64_t(0.9 * lap_s * double(kNsPerS)); t += kTruthStep) {
    const double a = kLaneSpeed * ns_to_s(t) / kCircleRadius;
    const double r = kCircleRadius - kInward * a / (2 * kPi) - kInside;
    truth.push_back({t, {r * std::cos(a), r * std::sin(a), wrap_angle(a + kPi / 2)}});
  }
  const std::vector<double> offsets = lane_offsets(truth, route);
  for (size_t i = 0; i < truth.size(); ++i) EXPECT_NEAR(offsets[i], kInside, kLaneTolerance) << "sample " << i;
}

TEST(LaneOffsets, AnOpenRouteEndsWhereItEnds) {
  // Most of the circle, open: its end is 8.7 m from its start. Driven once to the right of it, then
  // on past the end along its last segment: the projection stays at the end rather than wrapping to
  // the start, and the distance is to the last segment's line.
  constexpr double kArcDegrees = 350;
  constexpr double kRight = 0.2;  // m
  constexpr double kBeyondEnd_s = 1;
  const Path route = circle_route(kArcDegrees);
  ASSERT_FALSE(route.closed);
  std::vector<TruthPose> truth = circle_truth(0, route.length / kLaneSpeed, -kRight);
  const Pose2d end = route.pose_at(route.length);
  const Eigen::Vector2d right_of_end =
      Eigen::Vector2d(end.x, end.y) + kRight * Eigen::Vector2d(std::sin(end.yaw), -std::cos(end.yaw));
  const int64_t t_end = truth.back().stamp_ns;
  for (int64_t t = kTruthStep; t <= int64_t(kBeyondEnd_s * double(kNsPerS)); t += kTruthStep) {
    const Eigen::Vector2d p =
        right_of_end + kLaneSpeed * ns_to_s(t) * Eigen::Vector2d(std::cos(end.yaw), std::sin(end.yaw));
    truth.push_back({t_end + t, {p.x(), p.y(), end.yaw}});
  }

  const std::vector<double> offsets = lane_offsets(truth, route);
  ASSERT_EQ(offsets.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) EXPECT_NEAR(offsets[i], -kRight, kLaneTolerance) << "sample " << i;
  EXPECT_NEAR(score(truth, {}, route, {}, "m", "arc").metrics.max_lane_offset_m, kRight, kLaneTolerance);
}

}  // namespace
}  // namespace lidarloop
