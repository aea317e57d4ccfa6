#pragma once
// A log's scans, whichever way it holds them: as the clouds a driver made (sensor_msgs/PointCloud2 on
// /lidar/points), or, in a log recorded with `--packets-only`, only as the HDL-32E's raw packets
// (velodyne_msgs/VelodyneScan on /velodyne_packets), decoded here as a driver does with the sensor's
// calibration (common/hdl32e_driver.hpp). The simulator made its clouds the same way, so a
// packets-only log gives back the live run's clouds to the bit.
#include <optional>
#include <string>

#include "common/hdl32e_driver.hpp"
#include "common/point_cloud.hpp"
#include "logs/mcap/mcap_reader.hpp"

namespace lidarloop {

// The scan `message` (read by `reader`) carries, or nullopt for a message that is none. With `topic`
// empty, a scan is a message on /lidar/points, or on /velodyne_packets in a log without /lidar/points
// (a log with both writes its first cloud before its first packets, so the points' channel is known
// by then and no scan is counted twice). With `topic` given, a PointCloud2 or VelodyneScan on it.
// InputError "<reader's path> <topic>: ..." for a malformed message.
std::optional<PointCloud> scan_message(const McapReader& reader, const McapMessage& message,
                                       const Hdl32eCalibration& calibration, const std::string& topic = "");

}  // namespace lidarloop
