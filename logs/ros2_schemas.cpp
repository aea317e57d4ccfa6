#include "logs/ros2_schemas.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lidarloop::ros2 {

namespace {

// Each type's own definition, keyed "pkg/Type". Field types name nested types in full ("pkg/Type"),
// which every parser resolves without package-relative lookups.
const std::map<std::string, std::string>& definitions() {
  static const std::map<std::string, std::string> defs = {
      {"builtin_interfaces/Time",
       "int32 sec\n"
       "uint32 nanosec\n"},
      {"std_msgs/Header",
       "builtin_interfaces/Time stamp\n"
       "string frame_id\n"},
      {"sensor_msgs/PointField",
       "uint8 INT8    = 1\n"
       "uint8 UINT8   = 2\n"
       "uint8 INT16   = 3\n"
       "uint8 UINT16  = 4\n"
       "uint8 INT32   = 5\n"
       "uint8 UINT32  = 6\n"
       "uint8 FLOAT32 = 7\n"
       "uint8 FLOAT64 = 8\n"
       "string name\n"
       "uint32 offset\n"
       "uint8  datatype\n"
       "uint32 count\n"},
      {"sensor_msgs/PointCloud2",
       "std_msgs/Header header\n"
       "uint32 height\n"
       "uint32 width\n"
       "sensor_msgs/PointField[] fields\n"
       "bool    is_bigendian\n"
       "uint32  point_step\n"
       "uint32  row_step\n"
       "uint8[] data\n"
       "bool is_dense\n"},
      {"sensor_msgs/NavSatStatus",
       "int8 STATUS_NO_FIX =  -1\n"
       "int8 STATUS_FIX =      0\n"
       "int8 STATUS_SBAS_FIX = 1\n"
       "int8 STATUS_GBAS_FIX = 2\n"
       "int8 status\n"
       "uint16 SERVICE_GPS =     1\n"
       "uint16 SERVICE_GLONASS = 2\n"
       "uint16 SERVICE_COMPASS = 4\n"
       "uint16 SERVICE_GALILEO = 8\n"
       "uint16 service\n"},
      {"sensor_msgs/NavSatFix",
       "std_msgs/Header header\n"
       "sensor_msgs/NavSatStatus status\n"
       "float64 latitude\n"
       "float64 longitude\n"
       "float64 altitude\n"
       "float64[9] position_covariance\n"
       "uint8 COVARIANCE_TYPE_UNKNOWN = 0\n"
       "uint8 COVARIANCE_TYPE_APPROXIMATED = 1\n"
       "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\n"
       "uint8 COVARIANCE_TYPE_KNOWN = 3\n"
       "uint8 position_covariance_type\n"},
      {"geometry_msgs/Point",
       "float64 x\n"
       "float64 y\n"
       "float64 z\n"},
      {"geometry_msgs/Vector3",
       "float64 x\n"
       "float64 y\n"
       "float64 z\n"},
      {"geometry_msgs/Quaternion",
       "float64 x 0\n"
       "float64 y 0\n"
       "float64 z 0\n"
       "float64 w 1\n"},
      {"geometry_msgs/Pose",
       "geometry_msgs/Point position\n"
       "geometry_msgs/Quaternion orientation\n"},
      {"geometry_msgs/PoseStamped",
       "std_msgs/Header header\n"
       "geometry_msgs/Pose pose\n"},
      {"geometry_msgs/PoseWithCovariance",
       "geometry_msgs/Pose pose\n"
       "float64[36] covariance\n"},
      {"geometry_msgs/PoseWithCovarianceStamped",
       "std_msgs/Header header\n"
       "geometry_msgs/PoseWithCovariance pose\n"},
      {"geometry_msgs/Twist",
       "geometry_msgs/Vector3 linear\n"
       "geometry_msgs/Vector3 angular\n"},
      {"geometry_msgs/TwistWithCovariance",
       "geometry_msgs/Twist twist\n"
       "float64[36] covariance\n"},
      {"geometry_msgs/Transform",
       "geometry_msgs/Vector3 translation\n"
       "geometry_msgs/Quaternion rotation\n"},
      {"geometry_msgs/TransformStamped",
       "std_msgs/Header header\n"
       "string child_frame_id\n"
       "geometry_msgs/Transform transform\n"},
      {"nav_msgs/Odometry",
       "std_msgs/Header header\n"
       "string child_frame_id\n"
       "geometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"lidarloop_msgs/VehicleReport",
       "# One vehicle report from the CAN bus (layout in lidarloop's assets/vehicle_can.dbc).\n"
       "# header.stamp: when the frame arrived (measurement time plus bus latency).\n"
       "std_msgs/Header header\n"
       "float64[4] wheel_speeds          # m/s: front left, front right, rear left, rear right\n"
       "float64 steering_wheel_angle     # rad, positive turns left (front wheel angle times the steering ratio)\n"},
      {"lidarloop_msgs/GnssHeading",
       "# Heading from a GNSS receiver, published next to its sensor_msgs/NavSatFix (same stamp).\n"
       "# ENU convention of REP 103: 0 = east, counter-clockwise positive.\n"
       "std_msgs/Header header\n"
       "float64 heading                  # rad\n"
       "float64 heading_variance         # rad^2\n"},
      {"lidarloop_msgs/TruthState",
       "# Simulator ground truth of the ego vehicle, lossless (nav_msgs/Odometry on /truth/odometry carries\n"
       "# the same pose for viewers). Vehicle frame origin: rear axle centre on the ground.\n"
       "std_msgs/Header header           # frame_id: map (local transverse Mercator frame, x east, y north)\n"
       "float64 x                        # m\n"
       "float64 y                        # m\n"
       "float64 yaw                      # rad, counter-clockwise from east\n"
       "float64 speed                    # m/s, longitudinal\n"
       "float64 yaw_rate                 # rad/s\n"
       "float64 steer                    # rad, front wheel angle\n"
       "float64 cross_track              # m, the path controller's lateral error to its route\n"},
      {"lidarloop_msgs/ActorState",
       "string name\n"
       "string type                      # car, bus, truck, pedestrian or cyclist\n"
       "float64 x                        # m, map frame\n"
       "float64 y                        # m\n"
       "float64 yaw                      # rad\n"},
      {"lidarloop_msgs/CurbVisibility",
       "# Simulator ground truth: how much of the curb within the localizer's curb range (1-25 m) the traffic\n"
       "# hid from the LiDAR at a scan's first firing (header.stamp), counted in curb-top samples 0.25 m apart.\n"
       "std_msgs/Header header\n"
       "int32 visible                    # samples the LiDAR sees\n"
       "int32 hidden                     # in sight of the static world, but an actor is in the way\n"
       "int32 blocked_by_world           # out of sight of the static world alone: in neither count\n"},
      // velodyne_msgs (ros-drivers/velodyne, ros2 branch): the sensor's raw data packets.
      {"velodyne_msgs/VelodynePacket",
       "builtin_interfaces/Time stamp\n"
       "uint8[1206] data\n"},
      {"velodyne_msgs/VelodyneScan",
       "std_msgs/Header header\n"
       "velodyne_msgs/VelodynePacket[] packets\n"},
      // diagnostic_msgs (ros2/common_interfaces): the localizer's health on /localizer/status.
      {"diagnostic_msgs/KeyValue",
       "string key\n"
       "string value\n"},
      {"diagnostic_msgs/DiagnosticStatus",
       "byte OK=0\n"
       "byte WARN=1\n"
       "byte ERROR=2\n"
       "byte STALE=3\n"
       "byte level\n"
       "string name\n"
       "string message\n"
       "string hardware_id\n"
       "diagnostic_msgs/KeyValue[] values\n"},
      {"diagnostic_msgs/DiagnosticArray",
       "std_msgs/Header header\n"
       "diagnostic_msgs/DiagnosticStatus[] status\n"},
      {"lidarloop_msgs/ActorArray",
       "# Simulator ground truth of the traffic actors, at each LiDAR scan's stamp.\n"
       "std_msgs/Header header\n"
       "lidarloop_msgs/ActorState[] actors\n"},
  };
  return defs;
}

// "pkg/msg/Type" -> "pkg/Type".
std::string short_name(const std::string& type) {
  const auto first = type.find('/');
  const auto last = type.rfind('/');
  if (first != last && type.compare(first, last - first + 1, "/msg/") == 0)
    return type.substr(0, first) + type.substr(last);
  return type;
}

// The nested types a definition uses, in order of first use.
std::vector<std::string> nested_types(const std::string& definition) {
  std::vector<std::string> out;
  std::istringstream lines(definition);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string type;
    if (!(words >> type) || type[0] == '#') continue;
    type = type.substr(0, type.find('['));
    if (type.find('/') != std::string::npos) out.push_back(type);
  }
  return out;
}

}  // namespace

std::string schema_text(const std::string& type) {
  const auto& defs = definitions();
  const std::string root = short_name(type);
  if (!defs.count(root)) throw std::invalid_argument("no ROS 2 definition for '" + type + "'");
  // Dependencies depth first in order of first use, each once: the order rosbag2 writes them in.
  std::vector<std::string> order;
  std::set<std::string> seen{root};
  std::function<void(const std::string&)> visit = [&](const std::string& t) {
    for (const auto& dep : nested_types(defs.at(t))) {
      if (!seen.insert(dep).second) continue;
      order.push_back(dep);
      visit(dep);
    }
  };
  visit(root);
  std::string text = defs.at(root);
  for (const auto& dep : order) text += "\n" + std::string(80, '=') + "\nMSG: " + dep + "\n" + defs.at(dep);
  return text;
}

std::vector<std::string> known_types() {
  std::vector<std::string> out;
  for (const auto& [name, def] : definitions())
    out.push_back(name.substr(0, name.find('/')) + "/msg" + name.substr(name.find('/')));
  return out;
}

}  // namespace lidarloop::ros2
