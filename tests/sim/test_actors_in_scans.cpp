// Actors in scans: a bus hides what is behind it, and a moving actor is seen where it is at each
// firing's own time.
#include <gtest/gtest.h>

#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

struct Box {
  Eigen::Vector3d lo, hi;
  // Slab test: does the segment a -> b cross the box?
  bool crossed_by(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    double t0 = 0, t1 = 1;
    for (int k = 0; k < 3; ++k) {
      const double d = b[k] - a[k];
      if (std::abs(d) < 1e-12) {
        if (a[k] < lo[k] || a[k] > hi[k]) return false;
        continue;
      }
      double ta = (lo[k] - a[k]) / d, tb = (hi[k] - a[k]) / d;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
};

Eigen::Isometry3d at(double x, double y, double yaw = 0) {
  return Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
}

TEST(ActorsInScans, AParkedBusHidesWhatIsBehindIt) {
  // A long wall 15 m to the right; the bus parked 5 m to the right, beside the sensor.
  TriangleMesh mesh = test::flat_ground(60);
  test::add_wall(mesh, {0, -15}, {50, 0.5f}, 8);
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const Eigen::Vector3d sensor = config.mount_xyz;
  // The bus body, shrunk by 0.2 m: the wheels and the gap under it are left out on purpose.
  const Box body{{-5.8, -6.08, 0.6}, {5.8, -3.92, 3.1}};
  auto count_through_body = [&](bool with_bus, int& wall_points) {
    RayScene scene(mesh);
    if (with_bus) {
      scene.add_actor(
          scene.add_prototype(load_actor_mesh(test::data_path("assets/actors"), ActorType::bus, test::materials())),
          at(0, -5));
      scene.commit();
    }
    const LidarScanner scanner(config, test::materials());
    const PointCloud cloud = scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, 1);
    int through = 0;
    wall_points = 0;
    for (const auto& p : cloud.points) {
      const Eigen::Vector3d world = sensor + Eigen::Vector3d(p.x, p.y, p.z);
      if (world.y() < -14.4) ++wall_points;
      if (world.y() < -6.5 && body.crossed_by(sensor, world)) ++through;
    }
    return through;
  };
  int wall_without = 0, wall_with = 0;
  EXPECT_GT(count_through_body(false, wall_without), 500);  // the shadow is not empty without the bus
  EXPECT_EQ(count_through_body(true, wall_with), 0);
  EXPECT_GT(wall_with, 1000);  // the rest of the wall is still seen
  EXPECT_LT(wall_with, wall_without);
}

TEST(ActorsInScans, AMovingActorIsSeenWhereItIsAtEachFiring) {
  // A 12 m bus drives past on the right at 10 m/s: it moves 1 m during the scan.
  const TriangleMesh ground = test::flat_ground(60);
  RayScene scene(ground);
  scene.add_actor(
      scene.add_prototype(load_actor_mesh(test::data_path("assets/actors"), ActorType::bus, test::materials())),
      at(-10, -5));
  scene.commit();
  const double speed = 10, half_length = 6.05;
  auto bus_x = [&](int64_t t_ns) { return -10.0 + speed * double(t_ns) * 1e-9; };
  const ActorPoses poses = [&](int64_t t, std::vector<Eigen::Isometry3d>& out) { out[0] = at(bus_x(t), -5); };
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const LidarScanner scanner(config, test::materials());
  const PointCloud cloud = scanner.scan(scene, constant_twist(Eigen::Isometry3d::Identity(), 0, 0, 0), 0, 1, poses);
  int on_bus = 0, beyond_start = 0;
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d w = config.mount_xyz + Eigen::Vector3d(p.x, p.y, p.z);
    if (w.z() < 0.5 || std::abs(w.y() + 5) > 1.4) continue;
    ++on_bus;
    // Every point of the bus lies within the bus's footprint at that point's own time.
    ASSERT_LT(std::abs(w.x() - bus_x(p.t_ns)), half_length + 0.01) << "t = " << p.t_ns;
    if (w.x() > -10 + half_length + 0.05) ++beyond_start;  // only possible because it moved
  }
  EXPECT_GT(on_bus, 1000);
  EXPECT_GT(beyond_start, 10);
}

}  // namespace
}  // namespace lidarloop
