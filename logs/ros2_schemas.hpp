#pragma once
// ROS 2 message definitions (`ros2msg` schema encoding) for the types lidarloop logs, in the form
// rosbag2 stores them: the message's own fields, then every nested type it uses, each after a line of
// 80 '=' and a "MSG: pkg/Type" line. Standard types are copied field for field from their ROS 2
// (Humble) packages, constants and default values included; lidarloop's own types (package
// lidarloop_msgs) are defined and documented here, since no standard message carries them.
#include <string>
#include <vector>

namespace lidarloop::ros2 {

// The complete schema text of `type` ("sensor_msgs/msg/PointCloud2" or "sensor_msgs/PointCloud2").
// std::invalid_argument for a type this file does not define.
std::string schema_text(const std::string& type);

// Every type schema_text() knows, as "pkg/msg/Type".
std::vector<std::string> known_types();

}  // namespace lidarloop::ros2
