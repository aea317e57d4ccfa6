// The MCAP reader as replay, score and export use it: a log read in file order, every message decoded
// by the project's CDR decoder for its type; then the summary as `info` reads it.
#include <functional>
#include <map>
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "logs/localizer_status.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/ros2_messages.hpp"

namespace {
using namespace lidarloop;
using Decoder = std::function<void(ros2::View, const std::string&)>;

const std::map<std::string, Decoder>& decoders() {
  static const std::map<std::string, Decoder> by_type = {
      {"sensor_msgs/msg/PointCloud2", [](auto v, auto& c) { ros2::decode_point_cloud(v, c); }},
      {"sensor_msgs/msg/NavSatFix", [](auto v, auto& c) { ros2::decode_nav_sat_fix(v, c); }},
      {"lidarloop_msgs/msg/GnssHeading", [](auto v, auto& c) { ros2::decode_gnss_heading(v, c); }},
      {"lidarloop_msgs/msg/VehicleReport", [](auto v, auto& c) { ros2::decode_vehicle_report(v, c); }},
      {"lidarloop_msgs/msg/TruthState", [](auto v, auto& c) { ros2::decode_truth_state(v, c); }},
      {"lidarloop_msgs/msg/CurbVisibility", [](auto v, auto& c) { ros2::decode_curb_visibility(v, c); }},
      {"lidarloop_msgs/msg/ActorArray", [](auto v, auto& c) { ros2::decode_actor_array(v, c); }},
      {"nav_msgs/msg/Odometry", [](auto v, auto& c) { ros2::decode_odometry(v, c); }},
      {"geometry_msgs/msg/PoseWithCovarianceStamped",
       [](auto v, auto& c) { ros2::decode_pose_with_covariance_stamped(v, c); }},
      {"geometry_msgs/msg/PoseStamped", [](auto v, auto& c) { ros2::decode_pose_stamped(v, c); }},
      {"tf2_msgs/msg/TFMessage", [](auto v, auto& c) { ros2::decode_tf(v, c); }},
      {"velodyne_msgs/msg/VelodyneScan", [](auto v, auto& c) { ros2::decode_velodyne_scan(v, c); }},
      {"diagnostic_msgs/msg/DiagnosticArray", [](auto v, auto& c) { decode_localizer_status(v, c); }},
  };
  return by_type;
}

void read_log(const std::string& path) {
  try {
    McapReader reader(path);
    McapMessage message;
    while (reader.next(message)) {
      if (!message.schema) continue;
      auto decoder = decoders().find(message.schema->name);
      if (decoder == decoders().end()) continue;
      try {
        decoder->second(message.data, path + " " + message.channel->topic);
      } catch (const InputError&) {
        // A message its schema does not describe: the reader of that topic says so; go on.
      }
    }
  } catch (const InputError&) {
  }
}

void read_summary(const std::string& path) {
  try {
    read_mcap_summary(path);
  } catch (const InputError&) {
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = (fuzz::scratch_dir() / "fuzz.mcap").string();
  fuzz::write_bytes(path, fuzz::as_text(data, size));
  read_log(path);
  read_summary(path);
  return 0;
}
