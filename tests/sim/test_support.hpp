#pragma once
// Shared fixtures for the unit tests: the project's materials, small hand-made scenes, and an
// HDL-32E configuration without randomness for exact checks.
#include <string>

#include "common/point_cloud.hpp"
#include "sim/hdl32e.hpp"
#include "sim/materials.hpp"
#include "sim/triangle_mesh.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop::test {

std::string data_path(const std::string& relative);  // inside the source tree
const MaterialTable& materials();
// A square of `material` at height z, centred on the origin.
TriangleMesh flat_ground(float half_size, const std::string& material = "asphalt", float z = 0);
// A vertical wall (thin box) of `material`.
void add_wall(TriangleMesh& mesh, const Eigen::Vector2f& centre, const Eigen::Vector2f& half_size, float height,
              const std::string& material = "building");
// A world built from YAML text (parse errors name `name`).
World world_from_yaml(const std::string& yaml, const std::string& name = "test_world.yaml");
// No noise, no random dropouts, every surface detected: geometry and timing become exact.
Hdl32eConfig noiseless_hdl32e();
// A point of a scan taken standing still, moved from where the driver reports it (its cycle's
// azimuth) onto its laser's true firing direction (the scan's start yaw turned on to the point's own
// firing time, in the mount frame, which absorbs the mean firing lag: sim/lidar_scanner.hpp): where
// the ray actually met the world, up to the 2 mm range step.
Eigen::Vector3d fired_point(const LidarPoint& p, const Hdl32eConfig& config);

}  // namespace lidarloop::test
