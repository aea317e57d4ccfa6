// Single-frame curb detection on simulated campus scans, against the curbs of the world itself.
#include <iostream>

#include <gtest/gtest.h>

#include "localizer/curb_detector.hpp"
#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/polyline.hpp"
#include "test_support.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

struct Detection {
  int detected = 0, correct = 0, expected = 0, found = 0;
};

// A scan from a car standing on the south straight of the campus loop (curbs at y = +-4.5).
Detection detect_on_straight(double x, const std::vector<std::pair<ActorType, Eigen::Isometry3d>>& traffic = {}) {
  static const LoadedWorld w = load_world(test::data_path("maps/campus/world.yaml"));
  RayScene scene(w.world.mesh);
  for (const auto& [type, pose] : traffic)
    scene.add_actor(scene.add_prototype(load_actor_mesh(test::data_path("assets/actors"), type, w.materials)), pose);
  scene.commit();
  const Hdl32eConfig config;  // the real noise and dropouts
  const LidarScanner scanner(config, w.materials);
  const Eigen::Isometry3d vehicle(Eigen::Translation3d(x, -2.25, 0));
  const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, 9);
  std::vector<Eigen::Vector3d> points;
  std::vector<uint16_t> rings;
  for (const auto& p : cloud.points) {
    points.push_back(config.mount() * Eigen::Vector3d(p.x, p.y, p.z));
    rings.push_back(p.ring);
  }
  const auto curbs = detect_curbs(points, rings, CurbDetectorParams{});
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
  // Recall: where each ground ring's circle crosses the two straight curbs, within 15 m, unless
  // something stands between the sensor and that point (a parked coach hides the curb behind it).
  const double height = config.mount_xyz.z();
  const Eigen::Vector3d sensor = vehicle * config.mount().translation();
  auto visible = [&](const Eigen::Vector2d& p) {
    constexpr double kNearTarget = 0.5;  // m: hits this close to the curb are the curb or the road by it
    const Eigen::Vector3d to = Eigen::Vector3d(p.x(), p.y(), 0.0) - sensor;
    const Ray ray{sensor.cast<float>(), to.normalized().cast<float>()};
    RayHit hit;
    return !scene.intersect(ray, 0.0f, float(to.norm() - kNearTarget), hit);
  };
  for (int ring = 0; ring < 32; ++ring) {
    const double elevation = config.elevation_deg[ring] * M_PI / 180;
    if (elevation >= 0) continue;
    const double r = height / std::tan(-elevation);
    for (double curb_y : {-4.5, 4.5}) {
      const double dy = curb_y - (-2.25), sensor_dx = config.mount_xyz.x();
      if (r <= std::abs(dy) || r > 15) continue;
      for (double sign : {-1.0, 1.0}) {
        const Eigen::Vector2d expected(x + sensor_dx + sign * std::sqrt(r * r - dy * dy), curb_y);
        if (!visible(expected)) continue;
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
  std::cout << "[ figures  ] curb detection with traffic: precision " << precision << " (" << correct << "/"
            << detected << "), recall of the curbs in view " << recall << " (" << found << "/" << expected
            << ")\n";
  EXPECT_GE(precision, 0.9);
  EXPECT_GE(recall, 0.8);
}

}  // namespace
}  // namespace lidarloop
