// The driver on its own: Eq. 19 vehicle + path controller on the campus loop's lane, no sensors.
#include <gtest/gtest.h>

#include "sim/controller.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

struct Drive {
  double cross_track_rms = 0, cross_track_max = 0, max_speed = 0;
  Pose2d end;
  std::vector<double> speeds;  // every 10 ms
  std::vector<Pose2d> poses;
};

Drive drive(const Path& path, double start_at, double speed, double initial_speed, double seconds,
            std::vector<Wait> stops = {}) {
  const VehicleParams vp;
  VehicleModel car(vp, VehicleModel::state_at(vp, path.pose_at(start_at), initial_speed));
  PathController controller(path, speed, std::move(stops), vp);
  Drive d;
  double sum2 = 0;
  int n = 0;
  ControllerCommand cmd;
  const int64_t control_every = 10;  // steps of 1 ms: the driver acts at 100 Hz, as in the simulator
  for (int64_t step = 0; step < int64_t(seconds * 1000); ++step) {
    if (step % control_every == 0) {
      cmd = controller.update(step * vp.step_ns, car.rear_axle_pose(), car.state().vx);
      sum2 += cmd.cross_track * cmd.cross_track, ++n;
      d.cross_track_max = std::max(d.cross_track_max, std::abs(cmd.cross_track));
      d.speeds.push_back(car.state().vx);
      d.poses.push_back(car.rear_axle_pose());
    }
    car.step(cmd.command);
    d.max_speed = std::max(d.max_speed, car.state().vx);
  }
  d.cross_track_rms = std::sqrt(sum2 / n);
  d.end = car.rear_axle_pose();
  return d;
}

const Path& campus_lane() {
  static const Path path = [] {
    const WorldDescription d = load_world_description(test::data_path("maps/campus/world.yaml"));
    return lane_path(*d.road("loop"), Lane::right, false);
  }();
  return path;
}

TEST(Controller, FollowsTheCampusLoopAt10MetresPerSecond) {
  // A whole lap: four 40 m curves, two long straights, at 10 m/s where the curves allow it.
  const Drive d = drive(campus_lane(), 100, 10.0, 10.0, 200);
  EXPECT_LT(d.cross_track_rms, 0.1);
  EXPECT_LT(d.cross_track_max, 0.3);
  EXPECT_NEAR(d.max_speed, 10.0, 0.3);
}

// Far off the path (a U-turn's wide exit, a start beside the lane) the cross-track feedback is capped
// (ControllerParams::max_cross_track_steer): the car comes back along a straight approach instead of
// swinging across the path in growing arcs while the steering actuator lags at its rate limit.
TEST(Controller, ComesBackFromThreeMetresOffWithoutSwingingAcross) {
  const Path path = make_path({{0, 0}, {400, 0}}, false);
  const VehicleParams vp;
  VehicleModel car(vp, VehicleModel::state_at(vp, {0, 3.0, 0}, 6.0));
  PathController controller(path, 6.0, {}, vp);
  double overshoot = 0, last = 0;
  ControllerCommand cmd;
  for (int64_t step = 0; step < 30000; ++step) {  // 30 s of 1 ms steps, the driver at 100 Hz
    if (step % 10 == 0) {
      cmd = controller.update(step * vp.step_ns, car.rear_axle_pose(), car.state().vx);
      overshoot = std::max(overshoot, -cmd.cross_track);  // started on the left: right of the path is overshoot
      last = cmd.cross_track;
    }
    car.step(cmd.command);
  }
  EXPECT_LT(overshoot, 0.3);
  EXPECT_LT(std::abs(last), 0.02);
}

TEST(Controller, StopsAtTheStopAndWaits) {
  const Drive d = drive(campus_lane(), 70, 8.0, 0.0, 25, {{120, 3.0}});
  const Eigen::Vector2d stop_point(campus_lane().pose_at(120).x, campus_lane().pose_at(120).y);
  double stopped = 0;
  for (size_t i = 0; i < d.speeds.size(); ++i)
    if (d.speeds[i] < 0.05 && i > 100) {
      stopped += 0.01;
      ASSERT_LT((Eigen::Vector2d(d.poses[i].x, d.poses[i].y) - stop_point).norm(), 0.5);
    }
  EXPECT_NEAR(stopped, 3.0, 0.3);
  EXPECT_GT(d.speeds.back(), 5.0);  // drove on afterwards
}

TEST(Controller, StopsAtTheEndOfAnOpenPath) {
  const Path straight = make_path({{0, 0}, {100, 0}}, false);
  const Drive d = drive(straight, 0, 10.0, 0.0, 30);
  EXPECT_NEAR(d.end.x, 100.0, 0.5);
  EXPECT_LT(d.speeds.back(), 0.05);
}

}  // namespace
}  // namespace lidarloop
