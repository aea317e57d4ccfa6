// Single-frame curb detection on simulated campus scans: against the curbs of the world itself, and
// against the oracle (tests/localizer/reference_curb_detector.hpp), which the fast detector must match
// bit for bit on scans with traffic all over the campus.
#include <array>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "localizer/curb_detector.hpp"
#include "localizer/obstacle_rejection.hpp"
#include "reference_curb_detector.hpp"
#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/path.hpp"
#include "sim/polyline.hpp"
#include "sim/road_surface.hpp"
#include "sim/vehicle_model.hpp"
#include "sim/world_assets.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

using Traffic = std::vector<std::pair<ActorType, Eigen::Isometry3d>>;

const LoadedWorld& campus() {
  static const LoadedWorld w = load_world(test::data_path("maps/campus/world.yaml"));
  return w;
}

// The campus on ideal ground (level, smooth, uniform vertical curbs, no cuts): the detector's own
// precision and recall, apart from what the road's realism costs it.
const LoadedWorld& ideal_campus() {
  static const LoadedWorld w = [] {
    LoadedWorld loaded = load_world(test::data_path("maps/campus/world.yaml"));
    loaded.description = on_ideal_ground(loaded.description);
    loaded.world = build_world(loaded.description, loaded.materials, test::data_path("assets/actors"));
    return loaded;
  }();
  return w;
}

// `w` with `traffic` standing in it, ready to scan.
std::unique_ptr<RayScene> scene_with(const LoadedWorld& w, const Traffic& traffic) {
  auto scene = std::make_unique<RayScene>(w.world.mesh);
  std::map<ActorType, int> prototypes;  // one mesh per type, however many actors share it
  const GroundHeight ground = w.world.ground();
  for (const auto& [type, pose] : traffic) {
    if (!prototypes.count(type))
      prototypes[type] = scene->add_prototype(load_actor_mesh(test::data_path("assets/actors"), type, w.materials));
    Eigen::Isometry3d on_ground = pose;  // standing on the crowned road or the sidewalk
    on_ground.translation().z() = ground(pose.translation().head<2>());
    scene->add_actor(prototypes[type], on_ground);
  }
  scene->commit();
  return scene;
}

// The detector's input: a scan from a car standing at `vehicle`, in the vehicle frame.
struct VehicleScan {
  std::vector<Eigen::Vector3d> points;
  std::vector<uint16_t> rings;
};

// The sensor these figures were first measured with: noise, dropouts, per-laser gains, no per-laser
// range biases and no mixed returns (the `ideal` profile's HDL-32E).
Hdl32eConfig clean_sensor() { return hdl32e_config_for(Realism::ideal); }

VehicleScan scan_from(RayScene& scene, const Eigen::Isometry3d& vehicle, uint64_t seed,
                      const Hdl32eConfig& config = clean_sensor()) {
  const LidarScanner scanner(config, campus().materials);
  const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, seed);
  VehicleScan scan;
  for (const auto& p : cloud.points) {
    scan.points.push_back(config.mount() * Eigen::Vector3d(p.x, p.y, p.z));
    scan.rings.push_back(p.ring);
  }
  return scan;
}

struct Detection {
  int detected = 0, correct = 0, expected = 0, found = 0;

  void add(const Detection& d) {
    detected += d.detected, correct += d.correct, expected += d.expected, found += d.found;
  }
  double precision() const { return double(correct) / detected; }
  double recall() const { return double(found) / expected; }
  std::string figures() const {
    return "precision " + std::to_string(precision()) + " (" + std::to_string(correct) + "/" +
           std::to_string(detected) + "), recall " + std::to_string(recall()) + " (" + std::to_string(found) + "/" +
           std::to_string(expected) + ")";
  }
};

// An east-west straight of a campus road: its centreline's y and half its width (curb to curb).
struct Straight {
  double y, half_width;
};
constexpr Straight kLoopSouth{0.0, 4.5};      // loop: vertical curbs, 0.3 m gutter, 2 % crown
constexpr Straight kWestStreet{200.0, 4.0};   // sloped curbs, 2 % crown
constexpr Straight kOneWayLane{200.0, 2.75};  // rolled curbs, 1.5 % crown

// A scan from a car standing `lane` metres left of the centreline of `road` at `x`, heading east.
// Precision: detections within kTolerance of any curb line of the world. Recall: where each
// downward laser's sweep crosses the foot of the straight's two curbs within 15 m, found by casting
// its rays (a parked coach hides the curb behind it; a rolled car's rings are not circles).
Detection detect_on_straight(const LoadedWorld& w, Straight road, double x, double lane, const Traffic& traffic = {},
                             const Hdl32eConfig& lidar = clean_sensor()) {
  const std::unique_ptr<RayScene> scene_owner = scene_with(w, traffic);
  RayScene& scene = *scene_owner;
  const VehicleParams car;
  const GroundHeight pavement = w.world.pavement(), ground = w.world.ground();
  const Eigen::Isometry3d vehicle = rest_on_ground({x, road.y + lane, 0}, pavement, car.wheelbase(), car.track_width);
  const VehicleScan scan = scan_from(scene, vehicle, 9, lidar);
  // As the localizer does: heights above the scan's ground plane (2.1.2), so a rolled car sees level.
  const ObstacleSplit split = reject_obstacles(scan.points, ObstacleParams{});
  const auto curbs =
      detect_curbs(split.plane_ok ? level_to_plane(scan.points, split.plane) : scan.points, scan.rings, {});
  Detection d;
  constexpr double kTolerance = 0.3;  // m from the true curb line
  for (const auto& c : curbs) {
    const Eigen::Vector2d world = (vehicle * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>();
    ++d.detected;
    double best = 1e9;
    for (const auto& line : w.world.curbs)
      best = std::min(best, (sample_polyline(line, project_onto_polyline(line, world)).point - world).norm());
    d.correct += best < kTolerance;
  }
  const Eigen::Isometry3d sensor = vehicle * lidar.mount();
  constexpr double kAzimuthStep = 0.001;  // rad
  for (int ring = 0; ring < 32; ++ring) {
    const double elevation = lidar.elevation_deg[ring] * M_PI / 180;
    if (elevation >= 0) continue;
    // Which side of each curb line the sweep was last seen on: a ray that grazes along a vertical face
    // hits the line itself, and only a change of side is a crossing.
    std::array<int, 2> side{0, 0};
    const std::array<double, 2> curb_ys{road.y - road.half_width, road.y + road.half_width};
    for (double a = 0; a < 2 * M_PI; a += kAzimuthStep) {
      const Eigen::Vector3d dir =
          sensor.linear() *
          Eigen::Vector3d(std::cos(elevation) * std::cos(a), std::cos(elevation) * std::sin(a), std::sin(elevation));
      RayHit hit;
      const Ray ray{sensor.translation().cast<float>(), dir.cast<float>()};
      if (!scene.intersect(ray, 0.0f, 40.0f, hit)) {
        side = {0, 0};
        continue;
      }
      const Eigen::Vector3d p = sensor.translation() + dir * double(hit.range);
      for (size_t k = 0; k < 2; ++k) {
        constexpr double kOnLine = 1e-4;  // m
        if (std::abs(p.y() - curb_ys[k]) < kOnLine) continue;
        const int now = p.y() > curb_ys[k] ? 1 : -1, before = std::exchange(side[k], now);
        if (before == 0 || before == now) continue;
        // The sweep crosses the curb line here: on the ground near the curb, within reach.
        if (std::abs(p.z() - pavement(p.head<2>())) > 0.3 ||
            (p.head<2>() - vehicle.translation().head<2>()).norm() > 15)
          continue;
        // Only where there is a step to see: not across a cut, a flare or a bus bay, where the
        // sidewalk comes down to the road.
        const Eigen::Vector2d expected(p.x(), curb_ys[k]), outward(0, curb_ys[k] > road.y ? 1 : -1);
        constexpr double kSidewalk = 0.6, kRoad = 0.5;  // m behind and in front of the curb line
        if (ground(expected + kSidewalk * outward) - ground(expected - kRoad * outward) <
            CurbDetectorParams{}.min_height)
          continue;
        ++d.expected;
        for (const auto& c : curbs)
          if (((vehicle * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>() - expected).norm() < 2 * kTolerance) {
            ++d.found;
            break;
          }
      }
    }
  }
  return d;
}

constexpr double kRightLane = -2.25;  // m left of the loop's centreline

TEST(CurbDetector, FindsTheCampusCurbsWithHighPrecisionAndRecall) {
  Detection all;
  for (double x : {160.0, 220.0, 380.0, 500.0})  // away from junctions
    all.add(detect_on_straight(ideal_campus(), kLoopSouth, x, kRightLane));
  std::cout << "[ figures  ] curb detection on ideal ground without traffic: " << all.figures() << "\n";
  EXPECT_GE(all.precision(), 0.9);
  EXPECT_GE(all.recall(), 0.8);
}

Eigen::Isometry3d parked(double x, double y, double yaw) {
  return Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

// A coach and a truck parked at the right curb, cars at the left one, a pedestrian on the road.
Traffic traffic_beside_the_curbs(double x) {
  return {{ActorType::bus, parked(x + 9, -3.1, 0)},
          {ActorType::truck, parked(x - 12, -3.1, 0)},
          {ActorType::car, parked(x + 4, 3.4, M_PI)},
          {ActorType::car, parked(x - 6, 3.4, M_PI)},
          {ActorType::pedestrian, parked(x + 3, 1.0, 1.0)}};
}

// Parked vehicles hide the road in front of the curb (no flat stretch to read a step from) and their
// sills and wheels make steps of their own. The floors are what the detector measured with this
// scene when they were set (precision 0.89, recall 0.63 of the crossings in view; the detector before
// the tilt-aware rise measured 0.86 and 0.64), a little lower, as regression guards.
TEST(CurbDetector, KeepsItsPrecisionAndRecallWithTrafficBesideTheCurbs) {
  Detection all;
  for (double x : {160.0, 380.0})
    all.add(detect_on_straight(ideal_campus(), kLoopSouth, x, kRightLane, traffic_beside_the_curbs(x)));
  std::cout << "[ figures  ] curb detection on ideal ground with traffic: " << all.figures() << "\n";
  EXPECT_GE(all.precision(), 0.85);
  EXPECT_GE(all.recall(), 0.6);
}

// The shipped campus, as scenarios drive it: crowned rough roads, gutters, sloped and rolled curbs,
// curb ramps and driveway cuts. Precision must stay what it is on ideal ground: a flare beside a ramp
// tilts 1:10 and must not pass for a curb (the rise is read where road and sidewalk meet the step).
// Recall counts only crossings where the ground steps up by min_height (not across cuts, flares or the
// bus bay). Its floors are regression guards a little under what the detector measured when they were
// set (0.78, 0.66, 0.85, 0.99; with traffic 0.79 / 0.70), not goals. Since points are placed as a
// driver decodes the HDL-32E's packets (all lasers of a cycle at its azimuth, sim/lidar_scanner.hpp)
// the traffic case measures 0.64 (36 of 56 crossings, was 39; the other cases moved by as much either
// way: 0.81, 0.64, 0.86, 0.99), so its floor is 0.6.
struct RealisticCase {
  const char* what;
  Straight road;
  std::vector<double> xs;
  double lane;
  double min_recall;
};

TEST(CurbDetector, KeepsItsPrecisionOnRealisticRoadsAndCurbs) {
  const std::vector<RealisticCase> cases = {
      {"crowned loop, vertical curbs behind a gutter", kLoopSouth, {160, 220, 380, 500}, kRightLane, 0.75},
      {"loop at crosswalk ramps, driveway cuts and a bus bay", kLoopSouth, {150, 450, 520, 570}, kRightLane, 0.6},
      {"west street, sloped curbs", kWestStreet, {60, 100, 240}, -2.0, 0.8},
      {"one-way lane, rolled curbs", kOneWayLane, {360, 450, 540}, 0.0, 0.95},
  };
  for (const RealisticCase& c : cases) {
    Detection d;
    for (double x : c.xs) d.add(detect_on_straight(campus(), c.road, x, c.lane));
    std::cout << "[ figures  ] " << c.what << ": " << d.figures() << "\n";
    EXPECT_GE(d.precision(), 0.9) << c.what;
    EXPECT_GE(d.recall(), c.min_recall) << c.what;
  }
  Detection traffic;
  for (double x : {160.0, 380.0})
    traffic.add(detect_on_straight(campus(), kLoopSouth, x, kRightLane, traffic_beside_the_curbs(x)));
  std::cout << "[ figures  ] crowned loop with traffic: " << traffic.figures() << "\n";
  EXPECT_GE(traffic.precision(), 0.75);
  EXPECT_GE(traffic.recall(), 0.6);
}

// The same traffic scenes through the `typical` HDL-32E: per-laser range biases, and mixed returns where
// a beam's spot straddles a vehicle's silhouette and the road behind it, which give ranges between the
// two (false steps at the feet of vehicles, as real detectors see). Floors a little under what was
// measured when they were set (ideal ground 0.82 / 0.63, crowned loop 0.74 / 0.70), as regression guards.
TEST(CurbDetector, TheTypicalSensorsMixedReturnsCostPrecisionBesideTraffic) {
  const Hdl32eConfig typical = hdl32e_config_for(Realism::typical);
  Detection ideal_ground, crowned;
  for (double x : {160.0, 380.0}) {
    ideal_ground.add(
        detect_on_straight(ideal_campus(), kLoopSouth, x, kRightLane, traffic_beside_the_curbs(x), typical));
    crowned.add(detect_on_straight(campus(), kLoopSouth, x, kRightLane, traffic_beside_the_curbs(x), typical));
  }
  std::cout << "[ figures  ] typical sensor, ideal ground with traffic: " << ideal_ground.figures() << "\n"
            << "[ figures  ] typical sensor, crowned loop with traffic: " << crowned.figures() << "\n";
  EXPECT_GE(ideal_ground.precision(), 0.8);
  EXPECT_GE(ideal_ground.recall(), 0.6);
  EXPECT_GE(crowned.precision(), 0.7);
  EXPECT_GE(crowned.recall(), 0.65);
}

// A car standing in the right lane of a campus road, `s` metres along it (driven backward: against
// the centreline's direction).
struct Stop {
  std::string road;
  bool backward;
  double s;
};

// Traffic around a stop, placed in the lane's own frame at some metres ahead (negative: behind), so it
// follows the road round its corners: parked vehicles at the right curb, a car coming the other way,
// a pedestrian crossing. A parked vehicle's body and wheels give a ground ring the steps a curb gives.
void add_traffic(const RoadSpec& road, const Path& lane, double s, bool truck, Traffic& traffic) {
  const double lane_width = road.width / road.lanes, to_right_curb = lane_width / 2;
  auto at = [&](double ahead, double left, double yaw) {
    const Pose2d p = lane.pose_at(s + ahead);
    const Eigen::Vector2d side(-std::sin(p.yaw), std::cos(p.yaw));
    const Eigen::Vector2d xy = Eigen::Vector2d(p.x, p.y) + left * side;
    return Eigen::Isometry3d(Eigen::Translation3d(xy.x(), xy.y(), 0) *
                             Eigen::AngleAxisd(p.yaw + yaw, Eigen::Vector3d::UnitZ()));
  };
  traffic.push_back({ActorType::car, at(8, -(to_right_curb - 1.0), 0)});
  traffic.push_back({truck ? ActorType::truck : ActorType::bus, at(-15, -(to_right_curb - 1.4), 0)});
  if (road.one_way)
    traffic.push_back({ActorType::cyclist, at(6, -(to_right_curb - 0.6), 0)});
  else
    traffic.push_back({ActorType::car, at(12, lane_width, M_PI)});
  traffic.push_back({ActorType::pedestrian, at(5, 0.5, M_PI / 2)});
}

TEST(CurbDetector, FindsExactlyTheOraclesCurbsOnCampusScansWithTraffic) {
  const LoadedWorld& w = campus();
  // Every road, both ways where it is two-way: the straights, the loop's rounded corners, junctions.
  std::vector<Stop> stops;
  for (int k = 0; k < 12; ++k) stops.push_back({"loop", false, 15 + 160.0 * k});
  for (int k = 0; k < 6; ++k) stops.push_back({"loop", true, 95 + 320.0 * k});
  for (const auto& [backward, s] : {std::pair{false, 40.0}, {false, 190.0}, {true, 120.0}, {true, 300.0}})
    stops.push_back({"central_avenue", backward, s});
  for (const auto& [backward, s] : {std::pair{false, 60.0}, {false, 240.0}, {true, 100.0}, {true, 180.0}})
    stops.push_back({"west_street", backward, s});
  for (double s : {30.0, 110.0, 190.0, 270.0}) stops.push_back({"one_way_lane", false, s});

  // All stops' traffic in one scene: built once, and each car sees the others' traffic if near.
  Traffic traffic;
  std::vector<Eigen::Isometry3d> vehicles;
  for (size_t k = 0; k < stops.size(); ++k) {
    const RoadSpec& road = *w.description.road(stops[k].road);
    const Path lane = lane_path(road, Lane::right, stops[k].backward);
    const VehicleParams car;
    vehicles.push_back(rest_on_ground(lane.pose_at(stops[k].s), w.world.pavement(), car.wheelbase(), car.track_width));
    add_traffic(road, lane, stops[k].s, k % 2 == 0, traffic);
  }
  const std::unique_ptr<RayScene> scene = scene_with(w, traffic);

  // Every stop has curbs in reach on both sides: 66 at the fewest (a rise is reported once for each
  // road point within step_length of it, so a curb crossing gives several).
  constexpr size_t kMinCurbsPerScan = 50;
  size_t curbs = 0;
  for (size_t k = 0; k < stops.size(); ++k) {
    SCOPED_TRACE(stops[k].road + (stops[k].backward ? " backward" : " forward") + " at " + std::to_string(stops[k].s) +
                 " m");
    const VehicleScan scan = scan_from(*scene, vehicles[k], 100 + k);
    const CurbDetectorParams params;
    const auto reference = test::reference_detect_curbs(scan.points, scan.rings, params);
    EXPECT_EQ(test::curb_difference(detect_curbs(scan.points, scan.rings, params), reference), "");
    EXPECT_GE(reference.size(), kMinCurbsPerScan);
    curbs += reference.size();
  }
  std::cout << "[ figures  ] " << stops.size() << " campus scans with " << traffic.size() << " actors: " << curbs
            << " curbs, the same in both detectors\n";
}

}  // namespace
}  // namespace lidarloop
