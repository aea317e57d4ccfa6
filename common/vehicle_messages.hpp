#pragma once
// Messages a real car gives a localizer besides its LiDAR scans: CAN vehicle reports, GPS fixes, and
// poses (ground truth, estimates). Times are nanoseconds since scenario start.
#include <array>
#include <cstdint>

#include <Eigen/Geometry>

#include "common/pose2d.hpp"

namespace lidarloop {

// One vehicle report from the CAN bus (layout in assets/vehicle_can.dbc).
struct CanFrame {
  int64_t stamp_ns = 0;                     // when it arrived (measurement time + bus latency)
  std::array<double, 4> wheel_speed_mps{};  // front left, front right, rear left, rear right
  double steering_wheel_angle_rad = 0;      // positive = turning left
};

enum class GpsStatus : int8_t { no_fix = -1, fix = 0, rtk = 2 };  // as sensor_msgs/NavSatStatus

struct GpsFix {
  int64_t stamp_ns = 0;
  GpsStatus status = GpsStatus::no_fix;
  double lat_deg = 0, lon_deg = 0, alt_m = 0;
  double heading_rad = 0;                       // yaw in the local frame (from +x east, counter-clockwise)
  std::array<double, 9> position_covariance{};  // m^2, east-north-up, row major (as NavSatFix)
  double heading_variance = 0;                  // rad^2
};

// The sprung body's attitude relative to the vehicle frame (the ground plane under the wheels): the
// body rotates about its centre of mass and heaves along the vehicle z. At rest (all zero) the body
// frame is the vehicle frame; the LiDAR is mounted on the body.
struct BodyAttitude {
  double heave = 0;  // m, the centre of mass's rise above its rest height
  double pitch = 0;  // rad, about the vehicle y axis: positive = nose down (as a dive under braking)
  double roll = 0;   // rad, about the vehicle x axis: positive = left side up (as in a left turn)
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  // the centre of mass at rest, vehicle frame, m

  // The body frame's pose in the vehicle frame: Translate(pivot + heave z) * Ry(pitch) * Rx(roll) *
  // Translate(-pivot).
  Eigen::Isometry3d pose() const {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.translate(pivot + Eigen::Vector3d(0, 0, heave));
    m.rotate(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
    m.translate(-pivot);
    return m;
  }
};

// The ground truth of the vehicle's state, as a simulator or an RTK/INS reference system gives it.
struct TruthSample {
  int64_t stamp_ns = 0;
  Pose2d pose;             // rear axle centre (the vehicle frame origin)
  double speed = 0;        // m/s
  double yaw_rate = 0;     // rad/s
  double steer = 0;        // front wheel angle, rad
  double cross_track = 0;  // the driver's lateral error to its route, m
  BodyAttitude body;       // the sprung body on its suspension (all zero for a rigid body)
};

}  // namespace lidarloop
