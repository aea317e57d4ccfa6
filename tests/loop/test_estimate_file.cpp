// An estimate from a localizer that is not ours: read from TUM or from an MCAP as rosbag2 records
// it (Odometry, PoseWithCovarianceStamped), scored with a known offset; its coverage by hand; and the
// log it is scored against, which must hold a ground truth.
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_writer.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/ros2_schemas.hpp"
#include "logs/tum_file.hpp"
#include "loop/recorded_log.hpp"
#include "loop/run_recording.hpp"
#include "scoring/estimate_file.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr double kHeading = 0.5;   // rad: a drive north-east, so lateral is not just y
constexpr double kLateral = 0.30;  // m to the left of the truth

std::string temp(const std::string& name) { return testing::TempDir() + "estimate_file_" + name; }

// 10 s at 10 m/s along kHeading, 100 Hz.
std::vector<TruthPose> truth() {
  std::vector<TruthPose> out;
  for (int64_t t = 0; t <= 10'000 * kMs; t += 10 * kMs) {
    const double s = 10.0 * double(t) / 1e9;
    out.push_back({t, {s * std::cos(kHeading), s * std::sin(kHeading), kHeading}});
  }
  return out;
}

// The truth at t, moved kLateral to its left.
Pose2d offset_pose(int64_t t) {
  const double s = 10.0 * double(t) / 1e9;
  return {s * std::cos(kHeading) - kLateral * std::sin(kHeading),
          s * std::sin(kHeading) + kLateral * std::cos(kHeading), kHeading};
}

Path route() { return make_path({{0, 0}, {200 * std::cos(kHeading), 200 * std::sin(kHeading)}}, false); }

// An MCAP as rosbag2 writes one: ros2msg schema, CDR messages, a topic of `type` with estimates at
// 10 Hz stamped 50 ms into each scan; `pose` makes each message from its stamp.
void write_mcap(const std::string& path, const std::string& type, const std::string& topic,
                const std::function<ros2::Bytes(int64_t)>& message) {
  McapWriter w(path);
  const uint16_t schema = w.add_schema(type, "ros2msg", ros2::schema_text(type));
  const uint16_t channel = w.add_channel(schema, topic, "cdr");
  const uint16_t other = w.add_channel(w.add_schema("std_msgs/msg/Header", "ros2msg", ""), "/other", "cdr");
  for (int64_t t = 50 * kMs; t < 10'000 * kMs; t += 100 * kMs) {
    const ros2::Bytes bytes = message(t);
    w.write_message(channel, uint64_t(t), uint64_t(t), bytes);
  }
  w.write_message(other, 0, 0, ros2::Bytes{0, 1, 0, 0});
  w.close();
}

ros2::Odometry odometry_at(int64_t t) {
  Eigen::Matrix3d cov = Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal();
  return ros2::planar_odometry(t, offset_pose(t), cov, "map", "base_link");
}

void expect_offset_scored(const EstimateFile& file) {
  ASSERT_EQ(file.estimates.size(), 100u);
  const ScoredRun run = score(truth(), file.estimates, route(), {}, "external", "test");
  EXPECT_EQ(run.metrics.frames, 100u);
  EXPECT_NEAR(run.metrics.lateral_rmse_m, kLateral, 1e-6);
  EXPECT_NEAR(run.metrics.longitudinal_rmse_m, 0, 1e-6);
  EXPECT_NEAR(run.metrics.heading_rmse_deg, 0, 1e-6);
  EXPECT_TRUE(std::isnan(run.metrics.latency_p50_ms));  // not known from a file
  EXPECT_NEAR(file.estimates[0].covariance(0, 0), 0.04, 1e-15);
  EXPECT_NEAR(file.estimates[0].covariance(1, 1), 0.09, 1e-15);
  EXPECT_NEAR(file.estimates[0].covariance(2, 2), 0.01, 1e-15);
}

TEST(EstimateFile, McapWithPoseWithCovarianceStamped) {
  const std::string path = temp("pose.mcap");
  write_mcap(path, "geometry_msgs/msg/PoseWithCovarianceStamped", "/localization/pose",
             [](int64_t t) { return ros2::encode_pose_with_covariance_stamped(odometry_at(t)); });
  const EstimateFile file = read_estimate_file(path);  // the only candidate topic
  EXPECT_EQ(file.format, "MCAP");
  EXPECT_EQ(file.topic, "/localization/pose");
  expect_offset_scored(file);
}

// A lidarloop log's own estimate: each /localizer/odometry with what its /localizer/status says (the
// health in words, lost, the protection bounds), as the run had them; the status of a scan before the
// localizer had a pose has no odometry to go with. The level says the worst of the health.
TEST(EstimateFile, ALidarloopLogsEstimatesCarryTheirStatus) {
  LocalizerEstimate waiting, ok, degraded, lost;
  waiting.stamp_ns = 100 * kMs;
  waiting.health = kNotInitialized | kNoGps;
  ok.stamp_ns = 200 * kMs;
  ok.health = 0;
  ok.pose = offset_pose(ok.stamp_ns);
  ok.protection_lateral_m = 0.1 + 0.2;
  ok.protection_longitudinal_m = 0.45;
  degraded = ok;
  degraded.stamp_ns = 300 * kMs;
  degraded.health = kNoGps;
  lost = ok;
  lost.stamp_ns = 400 * kMs;
  lost.health = kLost | kNoGps;
  lost.wide_search = true;
  lost.protection_lateral_m = lost.protection_longitudinal_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(localizer_status(waiting).level, ros2::kDiagnosticStale);
  EXPECT_EQ(localizer_status(ok).level, ros2::kDiagnosticOk);
  EXPECT_EQ(localizer_status(degraded).level, ros2::kDiagnosticWarn);
  EXPECT_EQ(localizer_status(lost).level, ros2::kDiagnosticError);

  const std::string path = temp("lidarloop_log.mcap");
  {
    McapRecorder log(path, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero());
    for (const LocalizerEstimate& e : {waiting, ok, degraded, lost}) record_estimate(log, e);
  }
  const EstimateFile file = read_estimate_file(path, log_topics::estimate);
  ASSERT_EQ(file.estimates.size(), 3u);  // no pose before the localizer had one
  const EstimateRecord &a = file.estimates[0], &b = file.estimates[1], &c = file.estimates[2];
  EXPECT_EQ(a.stamp_ns, ok.stamp_ns);
  EXPECT_EQ(a.status, "ok");
  EXPECT_FALSE(a.lost);
  EXPECT_EQ(a.protection_lateral_m, ok.protection_lateral_m);  // every bit
  EXPECT_EQ(a.protection_longitudinal_m, 0.45);
  EXPECT_EQ(b.status, "no GPS");
  EXPECT_FALSE(b.lost);
  EXPECT_EQ(c.status, describe_health(lost.health));
  EXPECT_TRUE(c.lost);
  EXPECT_TRUE(std::isinf(c.protection_lateral_m) && std::isinf(c.protection_longitudinal_m));

  // The truth's odometry in the same log is not the localizer's: no status is put on it.
  const std::string other = temp("other_topic.mcap");
  write_mcap(other, "nav_msgs/msg/Odometry", "/localization/odometry",
             [](int64_t t) { return ros2::encode_odometry(odometry_at(t)); });
  EXPECT_TRUE(std::isnan(read_estimate_file(other).estimates.at(0).protection_lateral_m));
}

TEST(EstimateFile, McapWithOdometryAndAFullAttitude) {
  const std::string path = temp("odom.mcap");
  write_mcap(path, "nav_msgs/msg/Odometry", "/localization/odometry", [](int64_t t) {
    ros2::Odometry o = odometry_at(t);
    // A localizer with an IMU reports roll and pitch too: only the yaw is scored.
    o.orientation = Eigen::AngleAxisd(kHeading, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(-0.03, Eigen::Vector3d::UnitX());
    return ros2::encode_odometry(o);
  });
  expect_offset_scored(read_estimate_file(path, "/localization/odometry"));
}

TEST(EstimateFile, TumIsToldByContentAndHasNoCovariance) {
  const std::string path = temp("est.mcap");  // a TUM file whatever its name says
  std::ofstream out(path);
  for (int64_t t = 50 * kMs; t < 10'000 * kMs; t += 100 * kMs) {
    const Pose2d p = offset_pose(t);
    out << tum_line({t, {p.x, p.y, 0}, ros2::yaw_quaternion(p.yaw)}) << "\n";
  }
  out.close();
  const EstimateFile file = read_estimate_file(path);
  EXPECT_EQ(file.format, "TUM");
  ASSERT_EQ(file.estimates.size(), 100u);
  EXPECT_EQ(file.estimates[0].covariance, Eigen::Matrix3d::Zero());
  EXPECT_NEAR(score(truth(), file.estimates, route(), {}, "tum", "test").metrics.lateral_rmse_m, kLateral, 1e-6);
}

void expect_input_error(const std::function<void()>& f, const std::string& expected) {
  try {
    f();
    ADD_FAILURE() << expected << ": accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(EstimateFile, McapTopicsMustBeFoundAndUnambiguous) {
  const std::string path = temp("pose_only.mcap");
  write_mcap(path, "geometry_msgs/msg/PoseWithCovarianceStamped", "/localization/pose",
             [](int64_t t) { return ros2::encode_pose_with_covariance_stamped(odometry_at(t)); });
  expect_input_error([&] { read_estimate_file(path, "/odom"); },
                     path +
                         ": no nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped on topic "
                         "'/odom' (topics: /localization/pose, /other)");
  const std::string none = temp("no_pose.mcap");
  write_mcap(none, "nav_msgs/msg/Odometry", "/a", [](int64_t) { return ros2::Bytes{0, 1, 0, 0, 1}; });
  expect_input_error([&] { read_estimate_file(none); }, none + ": message 1 on /a");  // a message too short

  // Two candidates: name one.
  const std::string two = temp("two.mcap");
  {
    McapWriter w(two);
    const uint16_t odom = w.add_schema("nav_msgs/msg/Odometry", "ros2msg", ros2::schema_text("nav_msgs/msg/Odometry"));
    const uint16_t a = w.add_channel(odom, "/a", "cdr"), b = w.add_channel(odom, "/b", "cdr");
    w.write_message(a, 0, 0, ros2::encode_odometry(odometry_at(0)));
    w.write_message(b, 0, 0, ros2::encode_odometry(odometry_at(0)));
    w.close();
  }
  expect_input_error([&] { read_estimate_file(two); },
                     two +
                         ": several nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped topics "
                         "(/a (nav_msgs/msg/Odometry), /b (nav_msgs/msg/Odometry)); name one with --topic");
  EXPECT_EQ(read_estimate_file(two, "/b").estimates.size(), 1u);

  // Stamps that go back, and a NaN.
  const std::string back = temp("back.mcap");
  write_mcap(back, "nav_msgs/msg/Odometry", "/o",
             [](int64_t t) { return ros2::encode_odometry(odometry_at(t == 550 * kMs ? 0 : t)); });
  expect_input_error([&] { read_estimate_file(back); }, back + ": message 6 on /o: header stamp 0.000000000 s");
  const std::string nan = temp("nan.mcap");
  write_mcap(nan, "nav_msgs/msg/Odometry", "/o", [](int64_t t) {
    ros2::Odometry o = odometry_at(t);
    o.position.x() = std::nan("");
    return ros2::encode_odometry(o);
  });
  expect_input_error([&] { read_estimate_file(nan); }, nan + ": message 1 on /o: a pose or covariance value");
  expect_input_error([&] { read_estimate_file(temp("absent.tum")); }, "absent.tum: cannot open file");
  expect_input_error([&] { read_estimate_file(testing::TempDir()); }, "is a folder, not a file (a rosbag2 bag?");
  std::ofstream(temp("tum_with_topic.tum")) << "0 0 0 0 0 0 0 1\n";
  expect_input_error([&] { read_estimate_file(temp("tum_with_topic.tum"), "/a"); }, "--topic applies to an MCAP");
}

// Coverage by hand: truth from 0 to 10 s, estimates every 100 ms from 2.05 s (a late start) to
// 8.95 s (an early stop) with the ones from 5.05 to 5.95 s missing (a gap). Each covers +-50 ms.
TEST(EstimateFile, CoverageOfALateGappyEarlyEndingEstimate) {
  std::vector<EstimateRecord> est;
  for (int64_t t = 2050 * kMs; t <= 8950 * kMs; t += 100 * kMs) {
    if (t >= 5050 * kMs && t <= 5950 * kMs) continue;
    EstimateRecord e;
    e.stamp_ns = t;
    e.pose = offset_pose(t);
    est.push_back(e);
  }
  // Covered: [2.0, 5.0] and [6.0, 9.0] = 6 s of 10 s. Gaps: 2.0 s before, 1.0 s inside, 1.0 s after.
  const Coverage c = estimate_coverage(truth(), est, 100 * kMs);
  EXPECT_DOUBLE_EQ(c.fraction, 0.6);
  EXPECT_DOUBLE_EQ(c.largest_gap_s, 2.0);
  PassThresholds t;
  t.min_coverage = 0.7;
  const Metrics m = score(truth(), est, route(), t, "x", "y").metrics;
  EXPECT_EQ(m.frames, est.size());  // scored on what exists
  EXPECT_NEAR(m.lateral_rmse_m, kLateral, 1e-6);
  EXPECT_DOUBLE_EQ(m.coverage, 0.6);
  ASSERT_EQ(m.failures.size(), 1u);
  EXPECT_EQ(m.failures[0], "coverage 0.600 < 0.700");
  t.min_coverage = 0.6;
  EXPECT_TRUE(score(truth(), est, route(), t, "x", "y").metrics.pass);

  // Every scan: full coverage and no gap, although the stamps sit mid-scan and past the truth's end.
  std::vector<EstimateRecord> all;
  for (int64_t s = 50 * kMs; s <= 10'050 * kMs; s += 100 * kMs) {
    all.emplace_back();
    all.back().stamp_ns = s;
    all.back().pose = offset_pose(s);
  }
  const Coverage full = estimate_coverage(truth(), all, 100 * kMs);
  EXPECT_DOUBLE_EQ(full.fraction, 1.0);
  EXPECT_DOUBLE_EQ(full.largest_gap_s, 0.0);
  // None, or no time span: nothing covered; undefined.
  EXPECT_DOUBLE_EQ(estimate_coverage(truth(), {}, 100 * kMs).fraction, 0.0);
  EXPECT_DOUBLE_EQ(estimate_coverage(truth(), {}, 100 * kMs).largest_gap_s, 10.0);
  EXPECT_TRUE(std::isnan(estimate_coverage({truth()[0]}, all, 100 * kMs).fraction));
}

TEST(RecordedLog, ALogWithoutTruthCannotBeScoredAgainst) {
  const std::string path = temp("no_truth.mcap");
  {
    McapWriter w(path);
    const std::string yaml = "world: campus\nduration_s: 1\nseed: 7\nego: {route: {road: loop, lane: right}}\n";
    w.add_attachment({0, 0, kScenarioAttachment, "application/yaml", {yaml.begin(), yaml.end()}});
    w.add_metadata(kRunMetadata, {{"seed", "7"}, {"method", "proposed"}});
    w.close();
  }
  expect_input_error([&] { read_recorded_log(path); }, path + ": no /truth/state messages to score against");
  const std::string plain = temp("plain.mcap");
  write_mcap(plain, "nav_msgs/msg/Odometry", "/o", [](int64_t t) { return ros2::encode_odometry(odometry_at(t)); });
  expect_input_error([&] { read_recorded_log(plain); }, "not a log recorded by lidarloop run or simulate");
}

}  // namespace
}  // namespace lidarloop
