// A kidnap (`faults:`) in the loop: the same short drive with and without one. Up to the kidnap the
// estimates are the same bits; at the scan that starts at its time (whatever the LiDAR clock's jitter
// did to the scan's stamp) the estimate has moved by the kidnap's offset in its own frame. The `gps`
// method fuses no scan, so nothing but the kidnap and the odometry of the scan's last instants moves
// that estimate.
#include <cmath>
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "common/units.hpp"
#include "loop/localizer_loop.hpp"
#include "loop/localizer_setup.hpp"

namespace lidarloop {
namespace {

constexpr double kKidnapS = 1.2;
constexpr int64_t kScanPeriodNs = 100'000'000;  // the HDL-32E at its default 10 Hz
const Eigen::Vector2d kOffset(3.0, -2.0);       // m, forward and left
constexpr double kYawDeg = 2.0;

// The scenario's world once for both drives (building it is most of the test's time).
const LoadedScenario& scenario() {
  static const LoadedScenario s = [] {
    const std::string path = testing::TempDir() + "kidnap_test.yaml";
    std::ofstream(path) << "world: campus\nduration_s: 1.8\nseed: 3\n"
                           "ego: {route: {road: loop, lane: right}, start_at: 80, speed: 10, initial_speed: 10}\n"
                           "localizer: {method: gps}\n";
    return load_scenario_and_world(path);
  }();
  return s;
}

std::vector<LocalizerEstimate> drive(const std::vector<KidnapFault>& kidnaps) {
  const LoadedScenario& s = scenario();
  Scenario with = s.scenario;
  with.kidnaps = kidnaps;
  HdMap map = open_scenario_map(with, s.world);
  Simulation sim(with, s.world.description, s.world.world, s.world.materials, actors_dir(), 1);
  return run_localizer_loop(sim, map, {localizer_params_for(with)}, false).methods.at(0).estimates;
}

TEST(Kidnap, MovesTheEstimateByItsOffsetAtTheScanThatStartsAtItsTime) {
  const std::vector<LocalizerEstimate> plain = drive({});
  const std::vector<LocalizerEstimate> kidnapped = drive({{kKidnapS, kOffset, kYawDeg * kDeg}});
  ASSERT_EQ(plain.size(), kidnapped.size());
  auto same = [](const Pose2d& a, const Pose2d& b) { return a.x == b.x && a.y == b.y && a.yaw == b.yaw; };
  size_t at = 0;
  while (at < plain.size() && same(plain[at].pose, kidnapped[at].pose)) ++at;
  ASSERT_LT(at, plain.size()) << "the kidnap moved nothing";
  ASSERT_GT(at, 0u);
  // An estimate is stamped at its scan's end (or at the last CAN frame, a few milliseconds later): the
  // one before the kidnap about at its time (its scan started a period before), the kidnapped one a
  // period after (its scan started at it).
  const int64_t due_ns = std::llround(kKidnapS * kNsPerS);
  EXPECT_LT(plain[at - 1].stamp_ns, due_ns + kScanPeriodNs / 2);
  EXPECT_GE(plain[at].stamp_ns, due_ns + kScanPeriodNs / 2);
  ASSERT_FALSE(plain[at].health & kNotInitialized);
  const Pose2d moved = plain[at].pose.inverse().compose(kidnapped[at].pose);
  std::cout << "[ figures  ] kidnap at scan " << at << " (estimate at " << ns_to_s(plain[at].stamp_ns)
            << " s): moved by " << moved.x << ", " << moved.y << " m, " << moved.yaw * kDegPerRad << " deg\n";
  // The pose is moved between the scan's CAN frames and its estimate: a few centimetres of driving
  // after the kidnap, turned by the kidnap's 2 degrees, are all that may differ.
  constexpr double kDrivenAfterM = 0.05;
  EXPECT_NEAR(moved.x, kOffset.x(), kDrivenAfterM);
  EXPECT_NEAR(moved.y, kOffset.y(), kDrivenAfterM);
  EXPECT_NEAR(moved.yaw, kYawDeg * kDeg, 1e-9);
}

}  // namespace
}  // namespace lidarloop
