// The scenario's kidnaps in the loop's time: each handed out once, at the scan that starts at its time
// (read from the scan's stamp on the LiDAR's clock), in order of time; only kidnaps of the belief, and
// none for an external program, whose belief cannot be moved (its car can).
#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "loop/kidnap_schedule.hpp"

namespace lidarloop {
namespace {

TEST(KidnapSchedule, HandsEachKidnapOutOnceAtTheScanThatStartsAtItsTime) {
  Scenario scenario;  // the HDL-32E at 10 Hz: a scan starts every 100 ms
  // Out of order in the file, two at the same time (done in file order).
  scenario.kidnaps = {{2.0, {1, 0}, 0.1}, {0.5, {0, 1}, 0}, {2.0, {0, 0}, -0.2}};
  KidnapSchedule s(scenario);
  EXPECT_TRUE(s.due(400'000'000).empty());  // the scan before
  // The scan that starts at 0.5 s, stamped a millisecond early by the LiDAR clock's jitter.
  const std::vector<Pose2d> first = s.due(499'000'000);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].y, 1.0);
  EXPECT_TRUE(s.due(600'000'000).empty());  // not twice
  const std::vector<Pose2d> both = s.due(2'001'000'000);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].x, 1.0);
  EXPECT_EQ(both[0].yaw, 0.1);
  EXPECT_EQ(both[1].yaw, -0.2);
  EXPECT_TRUE(s.due(9'000'000'000).empty());
  EXPECT_TRUE(KidnapSchedule().empty());

  // A kidnap of the car is the simulation's: the scans show it, the schedule does not hand it out.
  scenario.kidnaps = {{0.5, {1, 0}, 0, KidnapMoves::car}, {1.0, {0, 1}, 0}};
  KidnapSchedule beliefs_only(scenario);
  EXPECT_TRUE(beliefs_only.due(500'000'000).empty());
  ASSERT_EQ(beliefs_only.due(1'000'000'000).size(), 1u);
  scenario.kidnaps = {{0.5, {1, 0}, 0, KidnapMoves::car}};
  EXPECT_TRUE(KidnapSchedule(scenario).empty());

  // A LiDAR clock 20 ms late (a host stamp, `harsh`): the scan that starts at 1 s is stamped 1.02 s,
  // the one before 0.92 s, which is not yet due.
  scenario.clocks.lidar.offset_ns = 20'000'000;
  scenario.kidnaps = {{1.0, {1, 0}, 0}};
  KidnapSchedule late(scenario);
  EXPECT_TRUE(late.due(920'000'000).empty());
  EXPECT_EQ(late.due(1'020'000'000).size(), 1u);
}

TEST(KidnapSchedule, AnExternalProgramsBeliefCannotBeMovedButItsCarCan) {
  Scenario scenario;
  scenario.file = "kidnap.yaml";
  LocalizerParams external;
  external.external.command = {"my_localizer"};
  EXPECT_NO_THROW(check_kidnaps_supported(scenario, external));  // no kidnap: anything goes
  scenario.kidnaps = {{8.0, {3.5, -2.0}, 0.03}};
  EXPECT_NO_THROW(check_kidnaps_supported(scenario, LocalizerParams{}));
  try {
    check_kidnaps_supported(scenario, external);
    ADD_FAILURE() << "an external program was kidnapped";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "kidnap.yaml: faults: a kidnap that moves the belief needs a built-in localizer method"),
              std::string::npos)
        << e.what();
  }
  scenario.kidnaps = {{8.0, {3.5, 2.0}, 0.03, KidnapMoves::car}};
  EXPECT_NO_THROW(check_kidnaps_supported(scenario, external));
}

}  // namespace
}  // namespace lidarloop
