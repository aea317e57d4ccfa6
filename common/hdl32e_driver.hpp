#pragma once
// What a Velodyne driver makes of an HDL-32E revolution's blocks: the point cloud a localizer gets.
// The simulator builds its scans with this very function (sim/lidar_scanner.hpp), and a log's
// /velodyne_packets decode with it too, so a packets-only log gives back the live run's clouds to
// the bit (logs/scan_messages.hpp).
#include <array>
#include <cstdint>
#include <span>

#include "common/hdl32e_block.hpp"
#include "common/point_cloud.hpp"

namespace lidarloop {

// The calibration a driver holds (the ROS driver's 32db.yaml): per channel of a block (firing slot),
// the laser's ring (0 = lowest) and vertical angle; and the firing timing that dates each return.
struct Hdl32eCalibration {
  std::array<uint16_t, kHdl32eChannels> ring{};
  std::array<double, kHdl32eChannels> cos_elevation{}, sin_elevation{};
  int64_t firing_period_ns = 0;  // between two channels of a block
  int64_t cycle_period_ns = 0;   // between two blocks
};

// Every return of a revolution's `blocks` (distance 0 = none) as hdl32e_point() places it, in block
// order then channel order, stamped `stamp_ns` (the first block's first firing): a point's t_ns is
// its block's index times cycle_period_ns plus its channel times firing_period_ns.
PointCloud hdl32e_cloud(const Hdl32eCalibration& calibration, int64_t stamp_ns, std::span<const Hdl32eBlock> blocks);

}  // namespace lidarloop
