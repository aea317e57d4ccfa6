#pragma once
// The simulator's main loop: the ego driven by its controller through Eq. 19, traffic on its paths,
// and the sensors (HDL-32E, CAN, GPS, RTK truth) sampled at their own rates on an integer-nanosecond
// clock; kidnaps of the car (`faults:` with `moves: car`) between two scans. What it produces goes to a StreamSink, so
// file formats (CSV, MCAP) stay out of the loop.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/curb_visibility.hpp"
#include "common/point_cloud.hpp"
#include "sim/curb_visibility.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/scenario.hpp"
#include "sim/vehicle_body.hpp"

namespace lidarloop {

struct ActorSample {
  std::string name;
  ActorType type;
  Pose2d pose;
};

class StreamSink {
 public:
  virtual ~StreamSink() = default;
  virtual void on_truth(const TruthSample&) {}
  virtual void on_can(const CanFrame&) {}
  virtual void on_gps(const GpsFix&) {}
  virtual void on_rtk(const GpsFix&) {}
  // sensor_pose: the LiDAR's true pose in the world (true mount, sim/sensor_calibration.hpp) at the
  // scan's first firing on the reference clock; the cloud's stamp is the LiDAR clock's (sim/clocks.hpp).
  virtual void on_scan(const PointCloud&, const Eigen::Isometry3d& /*sensor_pose*/) {}
  // Right after on_scan: the same scan as the HDL-32E sends it (its blocks), on the reference clock
  // (the sensor's clock is GPS-disciplined; the cloud's stamp is the host's, sim/clocks.hpp).
  virtual void on_lidar_rotation(const Hdl32eRotation&, int64_t /*stamp_ns*/) {}
  virtual void on_actors(int64_t /*stamp_ns*/, const std::vector<ActorSample>&) {}
  // After each scan: how much of the curb in the localizer's range the traffic hid from the LiDAR at
  // the scan's first firing (sim/curb_visibility.hpp), stamped on the reference clock.
  virtual void on_curb_visibility(const CurbVisibility&) {}
};

class Simulation {
 public:
  Simulation(const Scenario& scenario, const WorldDescription& description, const World& world,
             const MaterialTable& materials, const std::string& actors_dir, int threads);
  ~Simulation();

  // The pose the controller steers on: ground truth unless set (closed loop feeds the estimate).
  void set_pose_source(std::function<Pose2d(int64_t t_ns, const Pose2d& truth)> source);

  // Advances the clock to `t_ns` (at most the scenario's end), emitting every sample due on the way.
  void advance_to(int64_t t_ns, StreamSink& sink);
  void run(StreamSink& sink, const std::function<void(double fraction)>& progress = {});

  int64_t now_ns() const { return now_; }
  int64_t end_ns() const { return scenario_.duration_ns(); }
  const Scenario& scenario() const { return scenario_; }
  const ResolvedScenario& resolved() const { return resolved_; }
  const VehicleModel& vehicle() const { return vehicle_; }
  const VehicleBody& body() const { return body_; }
  // This run's draw of the true sensor mounts against the nominal ones (the scenario's `mount_error`).
  const MountDraw& mount_draw() const { return mount_draw_; }

 private:
  void step(StreamSink& sink);
  void emit_scan(StreamSink& sink);
  bool kidnap_the_car();
  void start_trajectory_here();  // the scan being recorded starts from the car's pose now

  Scenario scenario_;
  ResolvedScenario resolved_;
  std::unique_ptr<RayScene> scene_;
  MountDraw mount_draw_;
  Eigen::Isometry3d true_lidar_mount_;
  CounterRng lidar_clock_rng_;  // the LiDAR clock's jitter, by scan index
  LidarScanner scanner_;
  Hdl32eRotation rotation_;  // the last scan's blocks, reused from scan to scan
  VehicleModel vehicle_;
  PathController controller_;
  CanModel can_;
  GpsModel gps_;
  RtkModel rtk_;
  ActorPoses actor_poses_;  // empty when no actor moves
  std::function<Pose2d(int64_t, const Pose2d&)> pose_source_;
  ControllerCommand command_;
  int64_t now_ = 0;
  int64_t control_period_ns_;
  GroundHeight ground_;    // where actors stand
  GroundHeight pavement_;  // where the ego's wheels roll
  VehicleBody body_;       // the sprung body the LiDAR is mounted on
  int64_t scan_index_ = 0;
  std::vector<Pose2d> trajectory_;                // rear-axle pose at every step of the scan being recorded
  std::vector<BodyAttitude> body_trajectory_;     // the body on the ground plane at the same steps
  std::vector<GroundContact> ground_trajectory_;  // the wheels' contact with the pavement at the same steps
  int64_t trajectory_start_ns_ = 0;
  std::vector<KidnapFault> car_kidnaps_;  // the scenario's kidnaps that move the car, by time
  size_t next_car_kidnap_ = 0;
  CurbVisibilityConfig curb_visibility_;
  std::vector<Eigen::Vector3f> curb_tops_;  // the world's curbs, sampled once
};

}  // namespace lidarloop
