#pragma once
// A bird's-eye PNG of one scan: points coloured by intensity, the curb map drawn over them, north up,
// centred on the sensor.
#include <string>

#include <Eigen/Geometry>

#include "common/curb_map_file.hpp"
#include "common/point_cloud.hpp"

namespace lidarloop {

struct BirdseyeOptions {
  double half_extent_m = 50.0;  // image covers +-half_extent around the sensor
  double metres_per_pixel = 0.1;
};

// `sensor_pose`: the sensor's pose in the world at the scan's stamp; points are placed with it (not
// de-skewed, so motion distortion shows as it would to a naive consumer).
void write_birdseye_png(const std::string& path, const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose,
                        const std::vector<Polyline2d>& curbs, const BirdseyeOptions& options = {});

}  // namespace lidarloop
