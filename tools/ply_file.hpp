#pragma once
// A LiDAR scan as a binary PLY file (opens in CloudCompare, MeshLab, Open3D): x, y, z (float, m, sensor
// frame), intensity (uchar), ring (ushort) and time (float, s since the scan's stamp).
#include <string>

#include "common/point_cloud.hpp"

namespace lidarloop {

void write_ply(const std::string& path, const PointCloud& cloud);
PointCloud read_ply(const std::string& path);  // reads what write_ply writes; InputError otherwise

}  // namespace lidarloop
