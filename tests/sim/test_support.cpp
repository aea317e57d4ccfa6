#include "test_support.hpp"

#include <cmath>

namespace lidarloop::test {

std::string data_path(const std::string& relative) { return std::string(LIDARLOOP_DATA_DIR) + "/" + relative; }

const MaterialTable& materials() {
  static const MaterialTable table = MaterialTable::load(data_path("assets/materials.yaml"));
  return table;
}

TriangleMesh flat_ground(float half_size, const std::string& material, float z) {
  TriangleMesh mesh;
  const MaterialId m = materials().id(material, "test");
  add_flat_quad(mesh,
                {Eigen::Vector2f(-half_size, -half_size), Eigen::Vector2f(half_size, -half_size),
                 Eigen::Vector2f(half_size, half_size), Eigen::Vector2f(-half_size, half_size)},
                z, m);
  return mesh;
}

void add_wall(TriangleMesh& mesh, const Eigen::Vector2f& centre, const Eigen::Vector2f& half_size, float height,
              const std::string& material) {
  add_box(mesh, centre, half_size, 0.0f, 0.0f, height, materials().id(material, "test"));
}

World world_from_yaml(const std::string& yaml, const std::string& name) {
  return build_world(parse_world_description(yaml, name), materials(), data_path("assets/actors"));
}

Hdl32eConfig noiseless_hdl32e() {
  Hdl32eConfig c = hdl32e_config_for(Realism::ideal);  // no per-laser biases, dropouts or mixed returns
  c.range_noise_m = 0;
  c.intensity_noise = 0;
  c.detection_softness = 0;
  c.dark_target_range_m = 1000;  // everything within max range is detected
  c.max_incidence_deg = 90;
  return c;
}

Eigen::Vector3d fired_point(const LidarPoint& p, const Hdl32eConfig& config) {
  const double fired_yaw =
      (config.scan_start_yaw_deg - 360.0 * config.rotation_hz * double(p.t_ns) * 1e-9 + config.mean_firing_lag_deg()) *
      M_PI / 180;
  const Eigen::Vector3d reported(p.x, p.y, p.z);
  return Eigen::AngleAxisd(fired_yaw - std::atan2(reported.y(), reported.x()), Eigen::Vector3d::UnitZ()) * reported;
}

}  // namespace lidarloop::test
