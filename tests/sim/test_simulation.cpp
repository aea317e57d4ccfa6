// The simulation loop end to end: the driver on the campus loop, a bus overtaking, stops, and
// determinism of every stream.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "sim/simulation.hpp"
#include "sim/world_assets.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

struct Recorder : StreamSink {
  std::vector<TruthSample> truth;
  std::vector<CanFrame> can;
  std::vector<GpsFix> gps, rtk;
  std::vector<std::pair<PointCloud, Eigen::Isometry3d>> scans;
  std::vector<CurbVisibility> curbs;
  void on_truth(const TruthSample& s) override { truth.push_back(s); }
  void on_can(const CanFrame& f) override { can.push_back(f); }
  void on_gps(const GpsFix& f) override { gps.push_back(f); }
  void on_rtk(const GpsFix& f) override { rtk.push_back(f); }
  void on_scan(const PointCloud& c, const Eigen::Isometry3d& pose) override { scans.emplace_back(c, pose); }
  void on_curb_visibility(const CurbVisibility& v) override { curbs.push_back(v); }
};

// Runs a scenario given as YAML on a world given by name or as YAML text.
Recorder simulate(const std::string& scenario_yaml, const std::string& world_yaml = "", int threads = 0) {
  const Scenario scenario = parse_scenario(scenario_yaml, "test_scenario.yaml");
  const WorldDescription description = world_yaml.empty() ? load_world_description(world_file(scenario.world))
                                                          : parse_world_description(world_yaml, "test_world.yaml");
  const World world = build_world(description, test::materials(), test::data_path("assets/actors"));
  Simulation sim(scenario, description, world, test::materials(), test::data_path("assets/actors"), threads);
  Recorder rec;
  sim.run(rec);
  return rec;
}

TEST(Simulation, TheEgoDrivesItsRouteAndStopsWhereTold) {
  const Recorder rec = simulate(R"(world: campus
duration_s: 20
ego: {route: {road: loop, lane: right}, start_at: 70, speed: 8, stops: [{at: 120, duration_s: 3}]}
)");
  double stopped = 0, sum2 = 0;
  for (const auto& s : rec.truth) {
    if (s.speed < 0.05 && s.stamp_ns > 2'000'000'000) stopped += 0.01;
    sum2 += s.cross_track * s.cross_track;
  }
  EXPECT_NEAR(stopped, 3.0, 0.3);
  EXPECT_LT(std::sqrt(sum2 / double(rec.truth.size())), 0.1);
  EXPECT_GT(rec.truth.back().speed, 5.0);  // drove on afterwards
  EXPECT_EQ(rec.scans.size(), 200u);
  EXPECT_EQ(rec.can.size(), 1999u);  // 100 Hz, the last one still on the bus (10 ms latency)
  EXPECT_EQ(rec.gps.size(), 200u);
}

TEST(Simulation, ABusOvertakingOnTheRightHidesTheRightCurb) {
  // A straight one-way road with two lanes: the ego in the left lane at 8 m/s, a coach overtaking in
  // the right lane at 12 m/s from 25 m behind; it is alongside from about 5 s to 8 s.
  const std::string world = R"(name: straight
origin: {lat: 31.0, lon: 121.0}
roads:
  - {name: main, points: [[0, 0], [500, 0]], width: 7.0, lanes: 2, one_way: true, marking: dashed, sidewalk_width: 3}
)";
  const Recorder rec = simulate(R"(world: straight
duration_s: 14
ego: {route: {road: main, lane: left}, start_at: 60, speed: 8, initial_speed: 8}
traffic:
  - {type: bus, path: {road: main, lane: right}, start_at: 35, speed: 12}
)",
                                world);
  ASSERT_EQ(rec.scans.size(), 140u);
  ASSERT_EQ(rec.curbs.size(), rec.scans.size());  // one curb visibility record per scan
  const double right_curb = -3.5, bus_y = -1.75;
  for (size_t k = 0; k < rec.scans.size(); k += 10) {
    const auto& [cloud, sensor] = rec.scans[k];
    const double t = double(cloud.stamp_ns) * 1e-9;
    const double ego_x = sensor.translation().x(), bus_x = 35 + 12 * t;
    int curb = 0, on_bus = 0;
    for (const auto& p : cloud.points) {
      const Eigen::Vector3d w = sensor * Eigen::Vector3d(p.x, p.y, p.z);
      if (std::abs(w.x() - ego_x) < 6 && std::abs(w.y() - right_curb) < 0.3 && w.z() > 0.03) ++curb;
      if (std::abs(w.x() - bus_x) < 7 && std::abs(w.y() - bus_y) < 1.5 && w.z() > 0.6) ++on_bus;
    }
    const bool alongside = std::abs(bus_x - ego_x) < 3;
    const bool far = std::abs(bus_x - ego_x) > 30;
    SCOPED_TRACE("t = " + std::to_string(t) + " s, bus " + std::to_string(bus_x - ego_x) + " m ahead");
    const CurbVisibility& v = rec.curbs[k];
    EXPECT_EQ(v.stamp_ns, int64_t(k) * 100'000'000);  // the scan's start on the reference clock (10 Hz)
    const double hidden = double(v.hidden) / double(v.hidden + v.visible);
    if (alongside) {
      EXPECT_GT(on_bus, 500);  // the bus is in the scan where it should be
      EXPECT_LT(curb, 10);     // and the right curb beside the ego is hidden
      // The bus's near side (0.5 m right of the centre line, 2.25 m from the LiDAR) subtends
      // +-6 m * 5.25 / 2.25 = +-14 m of the right curb (5.25 m away): 112 of the ~195 samples on it
      // within 25 m, and ~199 on the left curb: 28 % of them all.
      EXPECT_NEAR(hidden, 0.28, 0.05);
    }
    if (far) {
      EXPECT_GT(curb, 40);  // without the bus the curb face is plain to see
    }
    if (std::abs(bus_x - ego_x) > 35) {
      EXPECT_EQ(v.hidden, 0);  // no ray to a curb in range passes the bus
    }
  }
}

// Same scenario and seed: every stream identical, whatever the number of threads.
TEST(Simulation, SameSeedGivesIdenticalStreamsAtAnyThreadCount) {
  const std::string yaml = R"(world: campus
duration_s: 3
seed: 11
ego: {route: {road: loop, lane: right}, start_at: 60, speed: 10, initial_speed: 5}
traffic:
  - {type: car, path: {road: loop, lane: right}, start_at: 90, speed: 8}
  - {type: pedestrian, path: {crosswalk: 0}, speed: 1.4}
)";
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    return simulate(yaml, "", threads);
  };
  const Recorder a = run(1), b = run(2);
  ASSERT_EQ(a.truth.size(), b.truth.size());
  ASSERT_EQ(a.can.size(), b.can.size());
  ASSERT_EQ(a.gps.size(), b.gps.size());
  ASSERT_EQ(a.scans.size(), b.scans.size());
  for (size_t i = 0; i < a.truth.size(); ++i) ASSERT_EQ(a.truth[i].pose.x, b.truth[i].pose.x);
  for (size_t i = 0; i < a.can.size(); ++i) ASSERT_EQ(a.can[i].wheel_speed_mps, b.can[i].wheel_speed_mps);
  for (size_t i = 0; i < a.gps.size(); ++i) ASSERT_EQ(a.gps[i].lat_deg, b.gps[i].lat_deg);
  for (size_t i = 0; i < a.scans.size(); ++i) {
    const auto &pa = a.scans[i].first.points, &pb = b.scans[i].first.points;
    ASSERT_EQ(pa.size(), pb.size());
    for (size_t j = 0; j < pa.size(); ++j)
      ASSERT_TRUE(pa[j].x == pb[j].x && pa[j].y == pb[j].y && pa[j].z == pb[j].z &&
                  pa[j].intensity == pb[j].intensity && pa[j].t_ns == pb[j].t_ns);
  }
}

// A kidnap of the car: at the end of the scan from 2.9 s the car is set down 3.5 m ahead, 1.5 m left and
// turned 2 degrees, still moving; the truth from 3.0 s and the scan from 3.0 s come from the new place,
// the wheels never saw the move, the suspension felt no bump, and the car steers back to its lane.
TEST(Simulation, AKidnapOfTheCarMovesItAndItsSensorsBetweenTwoScans) {
  const std::string drive = R"(world: campus
duration_s: 6
seed: 5
ego: {route: {road: loop, lane: right}, start_at: 60, speed: 8, initial_speed: 8}
)";
  const Eigen::Vector2d offset(3.5, 1.5);
  const double yaw = 2.0 * kDeg;
  const Recorder plain = simulate(drive);
  const Recorder kidnapped = simulate(drive +
                                      "faults: [{kind: kidnap, at_s: 3.0, offset: [3.5, 1.5], yaw_deg: 2.0, "
                                      "moves: car}]\n");
  ASSERT_EQ(plain.truth.size(), kidnapped.truth.size());
  const auto at = [](const Recorder& r, int64_t t_ns) {
    for (const TruthSample& s : r.truth)
      if (s.stamp_ns == t_ns) return s;
    ADD_FAILURE() << "no truth at " << t_ns;
    return TruthSample{};
  };
  // Before: the same drive.
  EXPECT_EQ(at(plain, 2'990'000'000).pose.x, at(kidnapped, 2'990'000'000).pose.x);
  // At 3.0 s: where the plain drive is, moved by the offset in its vehicle frame, at the same speed.
  const TruthSample p = at(plain, 3'000'000'000), k = at(kidnapped, 3'000'000'000);
  const Eigen::Vector2d moved = Eigen::Rotation2Dd(p.pose.yaw) * offset;
  EXPECT_LT((Eigen::Vector2d(k.pose.x, k.pose.y) - Eigen::Vector2d(p.pose.x, p.pose.y) - moved).norm(), 1e-9);
  EXPECT_NEAR(wrap_angle(k.pose.yaw - p.pose.yaw), yaw, 1e-12);
  EXPECT_EQ(k.speed, p.speed);
  EXPECT_NEAR(at(kidnapped, 3'010'000'000).cross_track - at(plain, 3'010'000'000).cross_track, offset.y(), 0.1);
  // The scans: the one from 2.9 s is the plain drive's, the one from 3.0 s is cast from the new place (the
  // LiDAR sits ahead of the rear axle, so the turn moves it by up to 1.5 m x 2 deg more).
  ASSERT_EQ(plain.scans.size(), kidnapped.scans.size());
  EXPECT_TRUE(plain.scans[29].second.isApprox(kidnapped.scans[29].second));
  const Eigen::Vector3d shift = kidnapped.scans[30].second.translation() - plain.scans[30].second.translation();
  EXPECT_LT((shift.head<2>() - moved).norm(), 0.06) << shift.transpose();
  // The wheels did not turn on the way: the CAN frames measured across the move (they arrive 10 ms after)
  // report the plain drive's wheel speeds, give or take the driver's first reaction.
  ASSERT_EQ(plain.can.size(), kidnapped.can.size());
  size_t across = 0;
  for (size_t i = 0; i < plain.can.size(); ++i)
    if (plain.can[i].stamp_ns > 3'000'000'000 && plain.can[i].stamp_ns <= 3'050'000'000) {
      ++across;
      for (size_t w = 0; w < 4; ++w)
        EXPECT_NEAR(kidnapped.can[i].wheel_speed_mps[w], plain.can[i].wheel_speed_mps[w], 0.05);
    }
  EXPECT_EQ(across, 5u);
  // The body on its suspension: set down on the other ground (the crown's other slope, another height)
  // with the attitude it had on the old one, not jolted by the step between the two (without: 29 mm of
  // heave and 0.13 deg of pitch at 20 ms). Over the first 20 ms, before the driver's steering back rolls
  // it; what differs then is the roughness under the two places (0.6 mm, 0.02 deg).
  for (int64_t t = 3'000'000'000; t <= 3'020'000'000; t += 10'000'000) {
    const BodyAttitude &bp = at(plain, t).body, &bk = at(kidnapped, t).body;
    EXPECT_NEAR(bk.roll, bp.roll, 0.03 * kDeg) << t;
    EXPECT_NEAR(bk.pitch, bp.pitch, 0.05 * kDeg) << t;
    EXPECT_NEAR(bk.heave, bp.heave, 0.003) << t;
  }
  // And the driver steered back to its lane.
  EXPECT_LT(std::abs(kidnapped.truth.back().cross_track), 0.3);
}

}  // namespace
}  // namespace lidarloop
