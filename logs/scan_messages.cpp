#include "logs/scan_messages.hpp"

#include "logs/hdl32e_packets.hpp"
#include "logs/log_topics.hpp"
#include "logs/ros2_messages.hpp"

namespace lidarloop {
namespace {

bool has_channel(const McapReader& reader, const char* topic) {
  for (const auto& [id, channel] : reader.channels())
    if (channel.topic == topic) return true;
  return false;
}

}  // namespace

std::optional<PointCloud> scan_message(const McapReader& reader, const McapMessage& message,
                                       const Hdl32eCalibration& calibration, const std::string& topic) {
  const std::string& on = message.channel->topic;
  const bool chosen = topic.empty() ? on == log_topics::scan ||
                                          (on == log_topics::velodyne_packets && !has_channel(reader, log_topics::scan))
                                    : on == topic;
  if (!chosen || !message.schema) return std::nullopt;
  const std::string context = reader.path() + " " + on;
  if (message.schema->name == "sensor_msgs/msg/PointCloud2") return ros2::decode_point_cloud(message.data, context);
  if (message.schema->name != "velodyne_msgs/msg/VelodyneScan") return std::nullopt;
  const ros2::VelodyneScan scan = ros2::decode_velodyne_scan(message.data, context);
  return hdl32e_cloud(calibration, scan.stamp_ns, hdl32e_blocks(scan, context));
}

}  // namespace lidarloop
