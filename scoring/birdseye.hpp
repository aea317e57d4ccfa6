#pragma once
// A bird's-eye PNG of one scan: points coloured by intensity, the curb map drawn over them, north up,
// centred on the sensor.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/curb_map_file.hpp"
#include "common/point_cloud.hpp"
#include "common/vehicle_messages.hpp"

namespace lidarloop {

// Points to mark over the scan (world frame), e.g. detected curbs and obstacles.
struct BirdseyeMarks {
  std::string label;
  std::vector<Eigen::Vector2d> points;
  std::array<uint8_t, 3> bgr{0, 0, 255};
};

// A vehicle pose drawn as an arrow, e.g. ground truth and the estimate.
struct BirdseyePose {
  std::string label;
  Pose2d pose;
  std::array<uint8_t, 3> bgr{255, 255, 255};
};

struct BirdseyeOptions {
  double half_extent_m = 50.0;  // image covers +-half_extent around the sensor
  double metres_per_pixel = 0.1;
  std::vector<BirdseyeMarks> marks;
  std::vector<BirdseyePose> poses;
  std::string title;  // first line of the caption; the point count when empty
};

// `sensor_pose`: the sensor's pose in the world at the scan's stamp; points are placed with it (not
// de-skewed, so motion distortion shows as it would to a naive consumer).
void write_birdseye_png(const std::string& path, const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose,
                        const std::vector<Polyline2d>& curbs, const BirdseyeOptions& options = {});

}  // namespace lidarloop
