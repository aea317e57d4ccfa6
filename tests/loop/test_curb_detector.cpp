// Single-frame curb detection on simulated campus scans: against the curbs of the world itself, and
// against the oracle (tests/localizer/reference_curb_detector.hpp), which the fast detector must match
// bit for bit on scans with traffic all over the campus.
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>

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

// The campus with `traffic` standing in it, ready to scan.
std::unique_ptr<RayScene> campus_scene(const Traffic& traffic) {
  const LoadedWorld& w = campus();
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

VehicleScan scan_from(RayScene& scene, const Eigen::Isometry3d& vehicle, uint64_t seed) {
  const Hdl32eConfig config;  // the real noise and dropouts
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
};

// A scan from a car standing on the south straight of the campus loop (curbs at y = +-4.5).
Detection detect_on_straight(double x, const Traffic& traffic = {}) {
  const LoadedWorld& w = campus();
  const std::unique_ptr<RayScene> scene_owner = campus_scene(traffic);
  RayScene& scene = *scene_owner;
  const Hdl32eConfig config;
  const VehicleParams car;
  const GroundHeight pavement = w.world.pavement();
  const Eigen::Isometry3d vehicle = rest_on_ground({x, -2.25, 0}, pavement, car.wheelbase(), car.track_width);
  const VehicleScan scan = scan_from(scene, vehicle, 9);
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
  // Recall: where each downward laser's sweep reaches the foot of the two straight curbs within 15 m,
  // found by casting its rays (a parked coach hides the curb behind it; a rolled car's rings are not
  // circles).
  const Eigen::Isometry3d sensor = vehicle * config.mount();
  constexpr double kAzimuthStep = 0.001;  // rad
  for (int ring = 0; ring < 32; ++ring) {
    const double elevation = config.elevation_deg[ring] * M_PI / 180;
    if (elevation >= 0) continue;
    std::optional<Eigen::Vector3d> last;
    for (double a = 0; a < 2 * M_PI; a += kAzimuthStep) {
      const Eigen::Vector3d dir =
          sensor.linear() *
          Eigen::Vector3d(std::cos(elevation) * std::cos(a), std::cos(elevation) * std::sin(a), std::sin(elevation));
      RayHit hit;
      const Ray ray{sensor.translation().cast<float>(), dir.cast<float>()};
      std::optional<Eigen::Vector3d> p;
      if (scene.intersect(ray, 0.0f, 40.0f, hit)) p = sensor.translation() + dir * double(hit.range);
      for (double curb_y : {-4.5, 4.5}) {
        if (!p || !last || (p->y() - curb_y) * (last->y() - curb_y) > 0) continue;
        // The ray sweeps across the curb line there: on the ground near the curb, within reach.
        if (std::abs(p->z() - pavement(p->head<2>())) > 0.3 ||
            (p->head<2>() - vehicle.translation().head<2>()).norm() > 15)
          continue;
        const Eigen::Vector2d expected(p->x(), curb_y);
        ++d.expected;
        for (const auto& c : curbs)
          if (((vehicle * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>() - expected).norm() < 2 * kTolerance) {
            ++d.found;
            break;
          }
      }
      last = p;
    }
  }
  return d;
}

TEST(CurbDetector, FindsTheCampusCurbsWithHighPrecisionAndRecall) {
  int detected = 0, correct = 0, expected = 0, found = 0;
  for (double x : {160.0, 220.0, 380.0, 500.0}) {  // away from crosswalks and junctions
    const Detection d = detect_on_straight(x);
    detected += d.detected, correct += d.correct, expected += d.expected, found += d.found;
  }
  const double precision = double(correct) / detected, recall = double(found) / expected;
  std::cout << "[ figures  ] curb detection without traffic: precision " << precision << " (" << correct << "/"
            << detected << "), recall " << recall << " (" << found << "/" << expected << ")\n";
  EXPECT_GE(precision, 0.9);
  EXPECT_GE(recall, 0.8);
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

Eigen::Isometry3d parked(double x, double y, double yaw) {
  return Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

TEST(CurbDetector, KeepsItsPrecisionAndRecallWithTrafficBesideTheCurbs) {
  // A coach and a truck parked at the right curb, cars at the left one, a pedestrian on the road.
  int detected = 0, correct = 0, expected = 0, found = 0;
  for (double x : {160.0, 380.0}) {
    const Detection d = detect_on_straight(x, {{ActorType::bus, parked(x + 9, -3.1, 0)},
                                               {ActorType::truck, parked(x - 12, -3.1, 0)},
                                               {ActorType::car, parked(x + 4, 3.4, M_PI)},
                                               {ActorType::car, parked(x - 6, 3.4, M_PI)},
                                               {ActorType::pedestrian, parked(x + 3, 1.0, 1.0)}});
    detected += d.detected, correct += d.correct, expected += d.expected, found += d.found;
  }
  const double precision = double(correct) / detected, recall = double(found) / expected;
  std::cout << "[ figures  ] curb detection with traffic: precision " << precision << " (" << correct << "/" << detected
            << "), recall of the curbs in view " << recall << " (" << found << "/" << expected << ")\n";
  EXPECT_GE(precision, 0.9);
  EXPECT_GE(recall, 0.8);
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
  const std::unique_ptr<RayScene> scene = campus_scene(traffic);

  constexpr size_t kMinCurbsPerScan = 100;  // every stop has curbs in reach on both sides (200 at least)
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
