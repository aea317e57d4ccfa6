#pragma once
// The LiDAR scan message: what a Velodyne driver gives a localizer, in the sensor frame
// (x forward, y left, z up) of the instant each point was fired.
#include <algorithm>
#include <cstdint>
#include <vector>

namespace lidarloop {

struct LidarPoint {
  float x = 0, y = 0, z = 0;  // m, sensor frame at the firing time
  uint8_t intensity = 0;      // 0-100 diffuse reflectivity, 101-255 retro-reflectors
  uint16_t ring = 0;          // laser index by elevation: 0 = lowest beam (ROS velodyne convention)
  uint32_t t_ns = 0;          // firing time relative to the scan's stamp
};

struct PointCloud {
  int64_t stamp_ns = 0;  // time of the first firing of the scan, since scenario start
  std::vector<LidarPoint> points;
};

// The scan's last firing, after its stamp: a scan's pose is reported for stamp_ns plus this (by the
// built-in localizers, and by default for an external one's answer).
inline int64_t scan_duration_ns(const PointCloud& cloud) {
  uint32_t last = 0;
  for (const LidarPoint& p : cloud.points) last = std::max(last, p.t_ns);
  return int64_t(last);
}

}  // namespace lidarloop
