#pragma once
// Scan de-skew (beyond the paper, which treats a scan as one snapshot): a Velodyne reports each point
// in the sensor frame of its own firing instant, so a scan taken while driving is skewed (1 m over a
// 10 Hz scan at 10 m/s). With the vehicle's speed and yaw rate from CAN over the scan, every point is
// brought into the vehicle frame at one reference time, so the matchers see the world as it is.
#include <vector>

#include <Eigen/Geometry>

#include "common/point_cloud.hpp"

namespace lidarloop {

struct ScanMotion {
  double speed = 0;     // m/s along the vehicle's x (rear axle)
  double yaw_rate = 0;  // rad/s
};

// A scan in the vehicle frame, point by point with the laser and intensity that produced it, in firing
// order (curb detection walks the rings in that order).
struct ScanPoints {
  std::vector<Eigen::Vector3d> xyz;
  std::vector<uint16_t> ring;
  std::vector<uint8_t> intensity;
  size_t dropped = 0;  // non-finite points of the input that are not here

  size_t size() const { return xyz.size(); }
};

// Points of `cloud` in the vehicle frame (origin at the rear axle) at time `reference_ns` after the
// scan's stamp, assuming constant speed and yaw rate over the scan (a circular arc). `mount` is the
// LiDAR's pose in the vehicle frame. Non-finite points are dropped.
ScanPoints deskew(const PointCloud& cloud, const Eigen::Isometry3d& mount, const ScanMotion& motion,
                  int64_t reference_ns);

// Without motion compensation: every point through the mount only (what a naive consumer does).
ScanPoints to_vehicle_frame(const PointCloud& cloud, const Eigen::Isometry3d& mount);

}  // namespace lidarloop
