#include "loop/mapping_drive.hpp"

#include <cmath>
#include <sstream>

#include "sim/actor_assets.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/path.hpp"
#include "sim/traffic.hpp"

namespace lidarloop {

namespace {

constexpr double kTrafficSpacing = 45.0;  // m between oncoming vehicles
constexpr double kTrafficSpeed = 9.0;     // m/s
constexpr ActorType kTrafficTypes[] = {ActorType::car, ActorType::car, ActorType::truck, ActorType::bus};

struct LaneDrive {
  const RoadSpec* road;
  bool backward;
  Path path;
};

// Every lane to drive: right and left lanes of each travel direction that has them.
std::vector<LaneDrive> lanes(const WorldDescription& d) {
  std::vector<LaneDrive> out;
  for (const auto& road : d.roads) {
    const int per_direction = road.one_way ? road.lanes : std::max(1, road.lanes / 2);
    for (bool backward : {false, true}) {
      if (backward && road.one_way) continue;
      out.push_back({&road, backward, lane_path(road, Lane::right, backward)});
      if (per_direction >= 2) out.push_back({&road, backward, lane_path(road, Lane::left, backward)});
    }
  }
  return out;
}

}  // namespace

std::string MappingOptions::describe() const {
  std::ostringstream s;
  s << "traffic=" << traffic << " speed=" << speed << " resolution=" << resolution << " tile_cells=" << tile_cells
    << " max_ground_height=" << max_ground_height << " max_range=" << max_range << " seed=" << seed;
  return s.str();
}

IntensityMapBuilder run_mapping_drive(const WorldDescription& description, const World& world,
                                      const MaterialTable& materials, const std::string& actors_dir,
                                      const MappingOptions& o, const std::string& world_hash,
                                      const std::function<void(double)>& progress) {
  IntensityMapHeader header;
  header.world = description.name;
  header.world_hash = world_hash;
  header.build["mapping"] = o.describe();
  header.origin = description.origin;
  header.resolution_m = o.resolution;
  header.tile_cells = o.tile_cells;
  IntensityMapBuilder builder(header);

  const Hdl32eConfig lidar;
  const LidarScanner scanner(lidar, materials);
  const Eigen::Isometry3d mount = lidar.mount();
  const int64_t period = lidar.scan_period_ns();
  const auto drives = lanes(description);
  double total = 0, done = 0;
  for (const auto& d : drives) total += d.path.length;

  for (const auto& [road, backward, path] : drives) {
    // A fresh scene per lane, with oncoming traffic on the other side of this road if asked.
    RayScene scene(world.mesh);
    std::vector<ActorPlan> traffic;
    if (o.traffic && !road->one_way) {
      const Path other = lane_path(*road, Lane::right, !backward);
      for (double s = kTrafficSpacing / 2; s < other.length; s += kTrafficSpacing) {
        ActorPlan a;
        a.type = kTrafficTypes[traffic.size() % std::size(kTrafficTypes)];
        a.path = other;
        a.start_s = s;
        a.speed = kTrafficSpeed;
        traffic.push_back(a);
      }
      add_actors(scene, traffic, actors_dir, materials);
    }
    const ActorPoses actor_poses = actor_motion(traffic);
    const PoseAt vehicle = [&](int64_t t) { return to_isometry(path.pose_at(o.speed * double(t) * 1e-9)); };
    const int64_t scans = int64_t(path.length / o.speed / (double(period) * 1e-9));
    for (int64_t k = 0; k < scans; ++k) {
      const int64_t stamp = k * period;
      const PointCloud cloud = scanner.scan(scene, vehicle, stamp, o.seed, actor_poses);
      // Ground truth places each point with the pose at its own firing cycle.
      uint32_t cycle = UINT32_MAX;
      Eigen::Isometry3d sensor = Eigen::Isometry3d::Identity();
      // The survey car is level: a point higher than this in the sensor frame cannot be ground.
      const double max_sensor_z = o.max_ground_height - lidar.mount_xyz.z();
      for (const LidarPoint& p : cloud.points) {
        if (p.z > max_sensor_z || double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z > o.max_range * o.max_range)
          continue;
        const uint32_t c = uint32_t(p.t_ns / lidar.cycle_period_ns());
        if (c != cycle) cycle = c, sensor = vehicle(stamp + int64_t(c) * lidar.cycle_period_ns()) * mount;
        if (p.intensity > 100) continue;  // a sign or a reflector, not the road surface
        const Eigen::Vector3d local(p.x, p.y, p.z);
        const Eigen::Vector3d w = sensor * local;
        if (w.z() > o.max_ground_height) continue;
        builder.add(w.head<2>(), p.intensity);
      }
      if (progress) progress((done + o.speed * double(stamp) * 1e-9) / total);
    }
    done += path.length;
  }
  return builder;
}

}  // namespace lidarloop
