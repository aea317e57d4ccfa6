#pragma once
// Messages a real car gives a localizer besides its LiDAR scans: CAN vehicle reports, GPS fixes, and
// poses (ground truth, estimates). Times are nanoseconds since scenario start.
#include <array>
#include <cstdint>

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

// The ground truth of the vehicle's state, as a simulator or an RTK/INS reference system gives it.
struct TruthSample {
  int64_t stamp_ns = 0;
  Pose2d pose;             // rear axle centre (the vehicle frame origin)
  double speed = 0;        // m/s
  double yaw_rate = 0;     // rad/s
  double steer = 0;        // front wheel angle, rad
  double cross_track = 0;  // the driver's lateral error to its route, m
};

}  // namespace lidarloop
