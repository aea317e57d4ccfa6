// The reference a run is scored against beside the truth (scoring/reference_trajectory.hpp): its drawn
// error has the configured sigma and correlation time, and the scorer's figures against it are known
// by construction.
#include <cmath>
#include <numeric>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/units.hpp"
#include "scoring/paper_tables.hpp"
#include "scoring/reference_trajectory.hpp"
#include "scoring/result_files.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kTruthPeriodNs = 10 * kMs;      // the simulator's truth, 100 Hz
constexpr int64_t kEstimatePeriodNs = 100 * kMs;  // one estimate per scan, 10 Hz

ReferenceConfig rtk(double sigma_xy_m, double heading_sigma_deg, double correlation_s) {
  ReferenceConfig c;
  c.kind = ReferenceConfig::Kind::rtk;
  c.sigma_xy_m = sigma_xy_m;
  c.heading_sigma_rad = heading_sigma_deg * kDeg;
  c.correlation_s = correlation_s;
  return c;
}

std::vector<int64_t> regular_stamps(double seconds, int64_t period_ns) {
  std::vector<int64_t> stamps;
  for (int64_t t = 0; t <= int64_t(seconds * double(kNsPerS)); t += period_ns) stamps.push_back(t);
  return stamps;
}

// The three axes of the errors as separate series: x, y, yaw.
std::vector<std::vector<double>> axes_of(const std::vector<ReferenceError>& errors) {
  std::vector<std::vector<double>> axes(3);
  for (const ReferenceError& e : errors) {
    axes[0].push_back(e.x_m);
    axes[1].push_back(e.y_m);
    axes[2].push_back(e.yaw_rad);
  }
  return axes;
}

double mean_of(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()); }

double sample_sigma(const std::vector<double>& v) {
  const double mean = mean_of(v);
  double sum = 0;
  for (double x : v) sum += (x - mean) * (x - mean);
  return std::sqrt(sum / double(v.size()));
}

// The sample autocorrelation of `a` with `b` shifted by `lag` samples (the same series: autocorrelation).
double correlation_at(const std::vector<double>& a, const std::vector<double>& b, size_t lag) {
  const double ma = mean_of(a), mb = mean_of(b);
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i + lag < a.size(); ++i) ab += (a[i] - ma) * (b[i + lag] - mb);
  for (size_t i = 0; i < a.size(); ++i) aa += (a[i] - ma) * (a[i] - ma), bb += (b[i] - mb) * (b[i] - mb);
  return ab / std::sqrt(aa * bb);
}

// A long draw recovers the configured sigma and correlation time on every axis. The draw spans
// T = 3000 correlation times, so for a first-order Gauss-Markov process the sample sigma's relative
// spread (1 sigma) is sqrt(tau / (2 T)) = 1.3 %, and the sample autocorrelation at lag tau (1/e) has a
// spread of 1.4 % (Bartlett's formula), 3.8 % of the correlation time read from it. The tolerances,
// 5 % on sigma and 12 % on the correlation time, are about 3 of those spreads. Sampled at 10 Hz: the
// discretisation is exact at any rate, and 10 Hz keeps the draw to 900 000 samples per axis.
TEST(ReferenceErrors, ALongDrawRecoversItsSigmaAndCorrelationTime) {
  constexpr double kSigma_m = 0.03, kHeadingSigma_deg = 0.1, kCorrelation_s = 30;
  constexpr double kSpan_s = 3000 * kCorrelation_s;
  constexpr int64_t kPeriodNs = 100 * kMs;
  constexpr double kSigmaTolerance = 0.05, kCorrelationTolerance = 0.12, kIndependence = 0.05;
  const std::vector<ReferenceError> errors =
      reference_errors(regular_stamps(kSpan_s, kPeriodNs), rtk(kSigma_m, kHeadingSigma_deg, kCorrelation_s), 1);
  const auto axes = axes_of(errors);
  const double sigmas[3] = {kSigma_m, kSigma_m, kHeadingSigma_deg * kDeg};
  const size_t lag = size_t(kCorrelation_s * double(kNsPerS) / double(kPeriodNs));
  for (size_t a = 0; a < 3; ++a) {
    EXPECT_NEAR(sample_sigma(axes[a]), sigmas[a], kSigmaTolerance * sigmas[a]) << "axis " << a;
    EXPECT_LT(std::abs(mean_of(axes[a])), kSigmaTolerance * sigmas[a] * 2) << "axis " << a;  // zero mean
    // exp(-lag / tau) at lag tau: 1/e; the correlation time from it.
    const double tau_s = -kCorrelation_s / std::log(correlation_at(axes[a], axes[a], lag));
    // The measured figures, in --gtest_output's report.
    RecordProperty("sigma_over_configured_axis_" + std::to_string(a),
                   std::to_string(sample_sigma(axes[a]) / sigmas[a]));
    RecordProperty("correlation_s_axis_" + std::to_string(a), std::to_string(tau_s));
    EXPECT_NEAR(tau_s, kCorrelation_s, kCorrelationTolerance * kCorrelation_s) << "axis " << a;
    // Consecutive samples 0.1 s apart: exp(-0.1 / 30), the process's own one-step correlation.
    EXPECT_NEAR(correlation_at(axes[a], axes[a], 1), std::exp(-0.1 / kCorrelation_s), 1e-3) << "axis " << a;
  }
  // The three axes are independent.
  EXPECT_LT(std::abs(correlation_at(axes[0], axes[1], 0)), kIndependence);
  EXPECT_LT(std::abs(correlation_at(axes[0], axes[2], 0)), kIndependence);
  EXPECT_LT(std::abs(correlation_at(axes[1], axes[2], 0)), kIndependence);
}

TEST(ReferenceErrors, APureFunctionOfStampsConfigAndSeed) {
  const std::vector<int64_t> stamps = regular_stamps(60, kTruthPeriodNs);
  const ReferenceConfig config = rtk(0.03, 0.1, 30);
  const std::vector<ReferenceError> a = reference_errors(stamps, config, 7), b = reference_errors(stamps, config, 7),
                                    c = reference_errors(stamps, config, 8);
  ASSERT_EQ(a.size(), stamps.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].x_m, b[k].x_m);
    EXPECT_EQ(a[k].yaw_rad, b[k].yaw_rad);
  }
  EXPECT_NE(a[0].x_m, c[0].x_m);
  // A shorter drive is the longer one's beginning: sample k's draw does not depend on what follows.
  const std::vector<int64_t> first(stamps.begin(), stamps.begin() + 100);
  EXPECT_EQ(reference_errors(first, config, 7).back().y_m, a[99].y_m);
  // No spread, no error; a repeated stamp keeps its error.
  for (const ReferenceError& e : reference_errors(stamps, rtk(0, 0, 30), 7)) EXPECT_EQ(e.x_m + e.y_m + e.yaw_rad, 0.0);
  const std::vector<ReferenceError> repeated = reference_errors({0, kMs, kMs}, config, 7);
  EXPECT_EQ(repeated[1].x_m, repeated[2].x_m);
  EXPECT_THROW(reference_errors({kMs, 0}, config, 7), std::invalid_argument);
  EXPECT_THROW(reference_errors(stamps, rtk(-0.01, 0.1, 30), 7), std::invalid_argument);
  EXPECT_THROW(reference_errors(stamps, rtk(0.03, 0.1, 0), 7), std::invalid_argument);
}

// A curve (a 50 m circle at 10 m/s, 100 Hz): the truth's vehicle frame turns, so the reference's map-axis
// error lands on both vehicle axes.
std::vector<TruthPose> curved_truth(double seconds) {
  constexpr double kRadius_m = 50, kSpeed_mps = 10;
  std::vector<TruthPose> truth;
  for (int64_t t : regular_stamps(seconds, kTruthPeriodNs)) {
    const double angle = kSpeed_mps / kRadius_m * ns_to_s(t);
    truth.push_back({t, {kRadius_m * std::sin(angle), kRadius_m * (1 - std::cos(angle)), wrap_angle(angle)}});
  }
  return truth;
}

TEST(ReferenceTrajectory, TheTruthPlusItsErrorAtTheTruthsStamps) {
  const std::vector<TruthPose> truth = curved_truth(10);
  const ReferenceConfig config = rtk(0.03, 0.1, 30);
  const std::vector<TruthPose> reference = reference_trajectory(truth, config, 5);
  std::vector<int64_t> stamps;
  for (const TruthPose& t : truth) stamps.push_back(t.stamp_ns);
  const std::vector<ReferenceError> errors = reference_errors(stamps, config, 5);
  ASSERT_EQ(reference.size(), truth.size());
  for (size_t k = 0; k < truth.size(); ++k) {
    EXPECT_EQ(reference[k].stamp_ns, truth[k].stamp_ns);
    EXPECT_EQ(reference[k].pose.x, truth[k].pose.x + errors[k].x_m);
    EXPECT_EQ(reference[k].pose.y, truth[k].pose.y + errors[k].y_m);
    EXPECT_EQ(reference[k].pose.yaw, wrap_angle(truth[k].pose.yaw + errors[k].yaw_rad));
  }
  ReferenceConfig none = config;
  none.kind = ReferenceConfig::Kind::none;
  EXPECT_EQ(reference_trajectory(truth, none, 5).front().pose.x, truth.front().pose.x);
}

// Estimates that are the reference's poses, one per scan.
std::vector<EstimateRecord> estimates_at(const std::vector<TruthPose>& poses) {
  std::vector<EstimateRecord> out;
  for (const TruthPose& p : poses)
    if (p.stamp_ns % kEstimatePeriodNs == 0) {
      EstimateRecord e;
      e.stamp_ns = p.stamp_ns;
      e.pose = p.pose;
      out.push_back(e);
    }
  return out;
}

Path circle_route() {
  std::vector<Eigen::Vector2d> points;
  for (const TruthPose& t : curved_truth(30)) points.emplace_back(t.pose.x, t.pose.y);
  return make_path(points, false);
}

// An estimate that is the reference scores zero against it, and exactly the reference's own error
// against the truth; the truth's figures are the same whether a reference is given or not.
TEST(Score, AnEstimateEqualToTheReferenceScoresZeroAgainstItAndItsErrorAgainstTheTruth) {
  const std::vector<TruthPose> truth = curved_truth(30);
  // A large, quickly varying reference error, so that every figure is far from zero.
  const std::vector<TruthPose> reference = reference_trajectory(truth, rtk(0.05, 0.2, 5), 11);
  const std::vector<EstimateRecord> estimates = estimates_at(reference);
  PassThresholds none;
  const ScoredRun with = score(truth, estimates, circle_route(), none, "ref", "circle", {}, {},
                               Hdl32eConfig{}.scan_period_ns(), reference);
  const Metrics& m = with.metrics;
  ASSERT_TRUE(m.reference);
  const ReferenceAccuracy& r = *m.reference;
  EXPECT_EQ(m.frames, estimates.size());
  EXPECT_EQ(r.lateral_rmse_m, 0);
  EXPECT_EQ(r.longitudinal_rmse_m, 0);
  EXPECT_EQ(r.heading_rmse_deg, 0);
  EXPECT_EQ(r.max_position_error_m, 0);

  // The reference's error against the truth, by the scorer's convention, frame by frame.
  std::vector<double> lateral, longitudinal, heading_deg;
  for (const EstimateRecord& e : estimates) {
    const FrameError f = frame_error(truth_at(truth, e.stamp_ns), e.pose);
    lateral.push_back(f.lateral_m);
    longitudinal.push_back(f.longitudinal_m);
    heading_deg.push_back(f.heading_rad * kDegPerRad);
  }
  EXPECT_EQ(m.lateral_rmse_m, rmse(lateral));
  EXPECT_EQ(m.longitudinal_rmse_m, rmse(longitudinal));
  EXPECT_EQ(m.heading_rmse_deg, rmse(heading_deg));
  EXPECT_EQ(r.error_lateral_rms_m, m.lateral_rmse_m);
  EXPECT_EQ(r.error_longitudinal_rms_m, m.longitudinal_rmse_m);
  EXPECT_EQ(r.error_heading_rms_deg, m.heading_rmse_deg);
  EXPECT_GT(m.lateral_rmse_m, 0.01);  // the reference is off, so the estimate is
  EXPECT_GT(m.heading_rmse_deg, 0.02);

  // Without a reference: the same truth figures, bit for bit, and none against a reference.
  const Metrics without = score(truth, estimates, circle_route(), none, "ref", "circle").metrics;
  EXPECT_FALSE(without.reference);
  EXPECT_EQ(without.lateral_rmse_m, m.lateral_rmse_m);
  EXPECT_EQ(without.max_position_error_m, m.max_position_error_m);
  EXPECT_EQ(without.worst_frame_stamp_ns, m.worst_frame_stamp_ns);

  // The reference must be drawn at the truth's samples.
  std::vector<TruthPose> shifted = reference;
  shifted.back().stamp_ns += 1;
  EXPECT_THROW(
      score(truth, estimates, circle_route(), none, "ref", "circle", {}, {}, Hdl32eConfig{}.scan_period_ns(), shifted),
      std::invalid_argument);
}

// The accuracy thresholds are the truth's unless `against: reference`.
TEST(Score, AccuracyThresholdsAgainstTheTruthOrTheReference) {
  const std::vector<TruthPose> truth = curved_truth(10);
  const std::vector<TruthPose> reference = reference_trajectory(truth, rtk(0.05, 0.2, 5), 11);
  const std::vector<EstimateRecord> estimates = estimates_at(reference);
  PassThresholds tight;
  tight.lateral_rmse_m = tight.longitudinal_rmse_m = tight.max_position_error_m = 0.001;
  tight.heading_rmse_deg = 0.001;
  const auto run = [&](const PassThresholds& t, const std::vector<TruthPose>& ref) {
    return score(truth, estimates, circle_route(), t, "ref", "circle", {}, {}, Hdl32eConfig{}.scan_period_ns(), ref)
        .metrics;
  };
  const Metrics on_truth = run(tight, reference);
  EXPECT_FALSE(on_truth.pass);
  ASSERT_EQ(on_truth.failures.size(), 4u);
  EXPECT_EQ(on_truth.failures[0].rfind("lateral RMSE 0.", 0), 0u) << on_truth.failures[0];

  tight.against_reference = true;
  EXPECT_TRUE(run(tight, reference).pass);
  const Metrics missing = run(tight, {});
  EXPECT_FALSE(missing.pass);
  EXPECT_EQ(missing.failures,
            std::vector<std::string>{"the accuracy thresholds are against the reference, but the run has none"});
  // An estimate off the reference fails against it, by name.
  std::vector<EstimateRecord> off = estimates;
  for (EstimateRecord& e : off) e.pose.x += 0.5;
  const Metrics failing =
      score(truth, off, circle_route(), tight, "ref", "circle", {}, {}, Hdl32eConfig{}.scan_period_ns(), reference)
          .metrics;
  ASSERT_FALSE(failing.failures.empty());
  EXPECT_EQ(failing.failures[0].rfind("lateral RMSE against the reference 0.", 0), 0u) << failing.failures[0];
}

TEST(ResultFiles, TheReferenceInMetricsJsonAndTheTables) {
  const std::vector<TruthPose> truth = curved_truth(10);
  const ReferenceConfig config = rtk(0.03, 0.1, 30);
  const std::vector<TruthPose> reference = reference_trajectory(truth, config, 3);
  std::vector<EstimateRecord> estimates = estimates_at(reference);
  for (EstimateRecord& e : estimates) e.pose.y += 0.2;
  Metrics m = score(truth, estimates, circle_route(), {}, "proposed", "circle", {}, {}, Hdl32eConfig{}.scan_period_ns(),
                    reference)
                  .metrics;
  m.reference->config = config;
  const auto j = nlohmann::json::parse(metrics_json(m));
  EXPECT_EQ(j["reference"]["kind"], "rtk");
  EXPECT_DOUBLE_EQ(j["reference"]["sigma_xy_m"].get<double>(), 0.03);
  EXPECT_NEAR(j["reference"]["heading_sigma_deg"].get<double>(), 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(j["reference"]["correlation_s"].get<double>(), 30);
  EXPECT_DOUBLE_EQ(j["reference"]["lateral_rmse_m"].get<double>(), m.reference->lateral_rmse_m);
  EXPECT_DOUBLE_EQ(j["reference"]["max_position_error_m"].get<double>(), m.reference->max_position_error_m);
  EXPECT_DOUBLE_EQ(j["reference"]["reference_error"]["lateral_rms_m"].get<double>(), m.reference->error_lateral_rms_m);
  EXPECT_EQ(j["thresholds"]["against"], "truth");

  const std::string table = reference_markdown({m});
  EXPECT_NE(table.find("| method | lateral RMSE m: truth | reference |"), std::string::npos) << table;
  EXPECT_NE(table.find("| proposed | "), std::string::npos) << table;
  EXPECT_EQ(reference_lines(m).rfind("reference  rtk (0.030 m per axis, 0.10 deg, correlation 30 s): against it "
                                     "lateral RMSE 0.",
                                     0),
            0u)
      << reference_lines(m);
  EXPECT_EQ(reference_lines(m, "proposed").rfind("reference  proposed: rtk (", 0), 0u);

  const std::vector<MethodOverSeeds> ours = summarise_over_seeds({m}, true);
  ASSERT_EQ(ours.size(), 1u);
  EXPECT_EQ(ours[0].lateral_m.mean, m.reference->lateral_rmse_m);
  EXPECT_EQ(summarise_over_seeds({m})[0].lateral_m.mean, m.lateral_rmse_m);

  // Without a reference: null, no table, no line, nothing summarised against one.
  const Metrics plain = score(truth, estimates, circle_route(), {}, "proposed", "circle").metrics;
  EXPECT_TRUE(nlohmann::json::parse(metrics_json(plain))["reference"].is_null());
  EXPECT_EQ(reference_markdown({plain}), "");
  EXPECT_EQ(reference_lines(plain), "");
  EXPECT_TRUE(summarise_over_seeds({plain}, true).empty());
}

}  // namespace
}  // namespace lidarloop
