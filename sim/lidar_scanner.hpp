#pragma once
// Casts HDL-32E scans into a RayScene.
//
// Motion distortion: every firing cycle is cast from the sensor pose at its own time, so a scan taken
// while driving or turning is skewed like a real one; within a cycle (36.9 us of firings) the origin
// moves on linearly. Points are reported in the sensor frame of their own firing instant, as a
// Velodyne driver reports them. Actors move during the scan too: their poses are keyframed every
// `cycles_per_actor_update` cycles and each ray meets them where they are at its own time.
//
// Reported geometry: each ray is cast in its laser's true direction at its true firing time, but the
// point reported is what a driver decodes from the sensor's packets (common/hdl32e_block.hpp): the
// cycle's azimuth on the 0.01 deg grid for all 32 lasers of the cycle, the range on the 2 mm grid,
// the laser's calibrated vertical angle. scan() can hand out those packet contents too.
//
// Output order is firing order, and each ray's noise comes from a counter-based generator keyed by the
// scan and the ray's index, so the cloud is identical whatever the number of threads.
//
// The sensor's own faults (sim/hdl32e.hpp): per-laser range biases and intensity offsets (in the
// return model), random dropouts, and mixed returns at depth edges, found after casting by comparing
// each firing with the same laser's previous and next firing (no extra rays). The weather
// (sim/weather.hpp): a wet road darkens road and marking materials, puddles on the carriageway return
// nothing, rain drops and the spray behind moving actors give spurious returns short of the surface.
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "common/hdl32e_block.hpp"
#include "common/point_cloud.hpp"
#include "sim/hdl32e.hpp"
#include "sim/lidar_return.hpp"
#include "sim/materials.hpp"
#include "sim/ray_scene.hpp"
#include "sim/weather.hpp"

namespace lidarloop {

// Vehicle pose in the world at a time (ns since scenario start).
using PoseAt = std::function<Eigen::Isometry3d(int64_t t_ns)>;
// Where the scene's actors are at a time: fills one pose per actor, in the scene's actor order.
using ActorPoses = std::function<void(int64_t t_ns, std::vector<Eigen::Isometry3d>& poses)>;

// A vehicle moving at constant speed and yaw rate on flat ground (a circular arc), from `start` at t0.
PoseAt constant_twist(const Eigen::Isometry3d& start, int64_t t0_ns, double speed_mps, double yaw_rate_radps);

using LidarRay = Ray;

class LidarScanner {
 public:
  LidarScanner(const Hdl32eConfig& config, const MaterialTable& materials, const WeatherConfig& weather = {});

  const Hdl32eConfig& config() const { return config_; }
  const WeatherConfig& weather() const { return weather_; }

  // The cloud is what a driver decodes from the scan's blocks (hdl32e_cloud). `wire`, when given,
  // receives those blocks as the sensor sends them, starting at stamp_ns.
  // Only the lasers whose bit (by laser id, 0-31) is set in `lasers` are cast; the others return
  // nothing. The random draws are by firing, so the lasers cast give the same returns either way.
  PointCloud scan(RayScene& scene, const PoseAt& vehicle_pose, int64_t stamp_ns, uint64_t seed,
                  const ActorPoses& actor_poses = {}, Hdl32eRotation* wire = nullptr,
                  uint32_t lasers = kAllLasers) const;
  static constexpr uint32_t kAllLasers = 0xffffffffu;

  // The rays of one scan in firing order (cycle-major, then firing slot); scan() casts exactly these.
  std::vector<LidarRay> rays(const PoseAt& vehicle_pose, int64_t stamp_ns) const;
  int rays_per_scan() const { return config_.cycles_per_scan() * kHdl32eLasers; }

 private:
  struct CyclePose {
    Eigen::Matrix3f rotation;
    Eigen::Vector3f origin, velocity;  // velocity carries the origin through the cycle
  };
  std::vector<CyclePose> cycle_poses(const PoseAt& vehicle_pose, int64_t stamp_ns) const;
  Eigen::Vector3f sensor_direction(int cycle, int slot) const;
  LidarRay ray(const CyclePose& pose, int cycle, int slot) const;
  // Where a beam's spot straddles a depth edge, moves its range towards the other surface's.
  void mix_depth_edges(const std::vector<float>& surface_range, const std::vector<float>& surface_signal,
                       const std::vector<uint8_t>& from_surface, const CounterRng& faults,
                       std::vector<float>& ranges) const;
  // A volume of spray behind a moving actor over one keyframe interval: world -> box frame, where the
  // box spans x in [-length, 0], |y| <= width / 2, z in [0, height]; density in returns per metre.
  struct SprayBox {
    Eigen::Isometry3f to_box;
    float length, density;
  };
  std::vector<SprayBox> spray_boxes(const std::vector<std::vector<Eigen::Isometry3d>>& motion) const;

  Hdl32eConfig config_;
  WeatherConfig weather_;
  std::vector<Material> materials_;   // as the weather makes them look (a wet road is darker)
  std::vector<uint8_t> carriageway_;  // per material: road surface that puddles cover
  ReturnModel returns_;
  Eigen::Isometry3d mount_;
  Hdl32eCalibration calibration_;  // how a driver decodes this unit's blocks
  // Per firing slot: the beam's unit vector at zero yaw, with the slot's own yaw advance folded in.
  std::array<Eigen::Vector3f, kHdl32eLasers> slot_direction_;
  std::vector<Eigen::Vector2f> cycle_yaw_;  // (cos, sin) of each cycle's starting yaw
  std::vector<uint16_t> cycle_azimuth_;     // each cycle's starting yaw as the encoder reports it
  int keyframes_ = 2;                       // actor keyframes per scan, evenly spaced from the stamp
  int64_t keyframe_step_ns_ = 0;
};

}  // namespace lidarloop
