#include "sim/sensor_calibration.hpp"

#include "common/units.hpp"
#include "sim/counter_rng.hpp"

namespace lidarloop {
namespace {

// The draw's own random stream, derived from the scenario seed: independent of every sensor's noise.
constexpr uint64_t kMountErrorStream = 0x6d6f756e74;  // "mount"
constexpr double kMaxRotationSigmaDeg = 10, kMaxTranslationSigmaM = 1;
// Draw indices of the nine normals: LiDAR roll, pitch, yaw; LiDAR x, y, z; antenna x, y, z.
constexpr uint64_t kLidarRotationDraw = 0, kLidarTranslationDraw = 3, kAntennaDraw = 6;

Eigen::Vector3d normals(const CounterRng& rng, uint64_t first) {
  return {rng.normal(first), rng.normal(first + 1), rng.normal(first + 2)};
}

Eigen::Vector3d read_sigmas(const YamlReader& y, const YAML::Node& n, const char* what, double hi) {
  const Eigen::Vector3d v = y.vec3(n, what);
  for (int i = 0; i < 3; ++i)
    if (!(v[i] >= 0 && v[i] <= hi)) y.fail(n, std::string(what) + " must be between 0 and " + std::to_string(hi));
  return v;
}

}  // namespace

MountErrorConfig mount_error_config_for(Realism realism) {
  MountErrorConfig c;
  switch (realism) {
    case Realism::ideal:
      c.lidar_rotation_sigma_rad.setZero();
      c.lidar_translation_sigma_m.setZero();
      c.gps_antenna_sigma_m.setZero();
      break;
    case Realism::typical:
      break;
    case Realism::harsh:
      c.lidar_rotation_sigma_rad.setConstant(0.02);   // arXiv 1905.04912: < 0.04 rad, read as 2 sigma
      c.lidar_translation_sigma_m.setConstant(0.05);  // arXiv 1905.04912: < 0.1 m, read as 2 sigma
      c.gps_antenna_sigma_m.setConstant(0.05);        // assumption: measured roughly
      break;
  }
  return c;
}

void read_mount_error(const YamlReader& y, const YAML::Node& node, MountErrorConfig& c) {
  YamlMap m(y, node, "mount_error");
  if (const YAML::Node r = m["lidar_rotation_deg"])
    c.lidar_rotation_sigma_rad = read_sigmas(y, r, "lidar_rotation_deg", kMaxRotationSigmaDeg) * kDeg;
  if (const YAML::Node t = m["lidar_translation_m"])
    c.lidar_translation_sigma_m = read_sigmas(y, t, "lidar_translation_m", kMaxTranslationSigmaM);
  if (const YAML::Node a = m["gps_antenna_m"])
    c.gps_antenna_sigma_m = read_sigmas(y, a, "gps_antenna_m", kMaxTranslationSigmaM);
  m.done();
}

MountDraw draw_mount_error(const MountErrorConfig& c, uint64_t scenario_seed) {
  const CounterRng rng(scenario_seed, kMountErrorStream);
  MountDraw d;
  d.lidar_rpy_rad = c.lidar_rotation_sigma_rad.cwiseProduct(normals(rng, kLidarRotationDraw));
  d.lidar_xyz_m = c.lidar_translation_sigma_m.cwiseProduct(normals(rng, kLidarTranslationDraw));
  d.gps_antenna_m = c.gps_antenna_sigma_m.cwiseProduct(normals(rng, kAntennaDraw));
  return d;
}

Hdl32eConfig with_true_mount(Hdl32eConfig nominal, const MountDraw& draw) {
  nominal.mount_xyz += draw.lidar_xyz_m;
  nominal.mount_rpy_deg += draw.lidar_rpy_rad / kDeg;
  return nominal;
}

GpsConfig with_true_antenna(GpsConfig nominal, const MountDraw& draw) {
  nominal.antenna_xyz += draw.gps_antenna_m;
  return nominal;
}

}  // namespace lidarloop
