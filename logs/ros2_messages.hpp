#pragma once
// lidarloop's messages as ROS 2 messages in CDR, and back. Times are nanoseconds since scenario
// start, carried in builtin_interfaces/Time (sec, nanosec), so a log's clock starts at 1970-01-01
// in viewers. Decoders check every length and throw InputError naming `context` (file, topic).
//
// Scans: sensor_msgs/msg/PointCloud2, one organised-as-a-row cloud (height 1, width = points),
// little endian, is_dense (a missing return is no point, never NaN), point_step 24:
//   offset  0  x          FLOAT32  m, LiDAR frame at the point's firing time
//   offset  4  y          FLOAT32
//   offset  8  z          FLOAT32
//   offset 12  intensity  FLOAT32  0-255 (integers: 0-100 diffuse, 101-255 retro-reflective), float as
//                                  in PCL's PointXYZI and the Velodyne ROS driver
//   offset 16  ring       UINT16   laser index by elevation, 0 = lowest (Velodyne driver convention)
//   offset 20  t_ns       UINT32   firing time, ns after header.stamp (the scan's first firing)
// Bytes 18-19 are zero padding that keeps t_ns aligned. The point time is an integer on purpose:
// replay must get every nanosecond back, which the Velodyne driver's float32 `time` in seconds
// cannot hold (its resolution near 0.1 s is 7 ns), and a second float field would cost a quarter
// more file (measured: 24 % larger zstd output). Ouster's driver and Autoware use uint32
// nanoseconds the same way (fields `t`, `time_stamp`).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "common/curb_visibility.hpp"
#include "common/point_cloud.hpp"
#include "common/vehicle_messages.hpp"

namespace lidarloop::ros2 {

inline constexpr uint32_t kPointStep = 24;

struct Stamp {
  int32_t sec = 0;
  uint32_t nanosec = 0;
};
Stamp to_stamp(int64_t ns);  // floor division: nanosec is always in [0, 1e9)
int64_t from_stamp(Stamp stamp);

using Bytes = std::vector<uint8_t>;
using View = std::span<const uint8_t>;

// sensor_msgs/msg/PointCloud2 in the layout above.
Bytes encode_point_cloud(const PointCloud& cloud, const std::string& frame_id);
// The same into `out`, reusing its allocation (a scan is about a megabyte).
void encode_point_cloud(const PointCloud& cloud, const std::string& frame_id, Bytes& out);
// Reads any little-endian PointCloud2 with FLOAT32/FLOAT64 x, y, z; intensity, ring and the point
// time are optional and converted from whatever numeric type they have. The time is taken from
// `t_ns`, `t` or `time_stamp` (nanoseconds), else from `time` (seconds, the Velodyne driver's).
PointCloud decode_point_cloud(View cdr, const std::string& context);

// sensor_msgs/msg/NavSatFix: status (service GPS), latitude, longitude, altitude, covariance (type
// KNOWN, or UNKNOWN without a fix). The heading goes separately as lidarloop_msgs/msg/GnssHeading.
Bytes encode_nav_sat_fix(const GpsFix& fix, const std::string& frame_id);
GpsFix decode_nav_sat_fix(View cdr, const std::string& context);  // heading fields left 0

struct GnssHeading {
  int64_t stamp_ns = 0;
  double heading = 0, variance = 0;
};
Bytes encode_gnss_heading(const GpsFix& fix, const std::string& frame_id);
GnssHeading decode_gnss_heading(View cdr, const std::string& context);

// lidarloop_msgs/msg/VehicleReport.
Bytes encode_vehicle_report(const CanFrame& frame, const std::string& frame_id);
CanFrame decode_vehicle_report(View cdr, const std::string& context);

// lidarloop_msgs/msg/TruthState (frame map).
Bytes encode_truth_state(const TruthSample& truth);
TruthSample decode_truth_state(View cdr, const std::string& context);

// lidarloop_msgs/msg/CurbVisibility (frame map).
Bytes encode_curb_visibility(const CurbVisibility& v);
CurbVisibility decode_curb_visibility(View cdr, const std::string& context);

// nav_msgs/msg/Odometry.
struct Odometry {
  int64_t stamp_ns = 0;
  std::string frame_id, child_frame_id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::array<double, 36> pose_covariance{};  // row major: x, y, z, rotation about x, y, z
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();  // child frame
  std::array<double, 36> twist_covariance{};
};
// A planar pose on the ground (z = 0, roll = pitch = 0). cov_xy_yaw is the covariance of (x, y, yaw)
// and fills the matching rows and columns (0, 1, 5) of the 6x6; the rest stays 0.
Odometry planar_odometry(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& cov_xy_yaw,
                         const std::string& frame_id, const std::string& child_frame_id);
Bytes encode_odometry(const Odometry& odom);
Odometry decode_odometry(View cdr, const std::string& context);
// The (x, y, yaw) block (rows and columns 0, 1, 5) of a 6x6 pose covariance: planar_odometry's inverse.
Eigen::Matrix3d planar_covariance(const std::array<double, 36>& pose_covariance);

// geometry_msgs/msg/PoseWithCovarianceStamped (what AMCL-like localizers publish), decoded as an
// Odometry with no child frame and no twist.
Bytes encode_pose_with_covariance_stamped(const Odometry& pose);
Odometry decode_pose_with_covariance_stamped(View cdr, const std::string& context);

// The one pair of functions every planar yaw goes through on its way into and out of a message or a
// TUM file: a rotation by `yaw` about z, and the yaw (rotation about z of the ZYX Euler angles) of any
// quaternion, unit or not (the formula is invariant to the quaternion's scale, so a quaternion
// written with few digits still gives its yaw). The live run scores published_yaw(yaw), the yaw as
// a reader of the log gets it back, so scoring the log's estimate gives the live run's numbers bit
// for bit.
Eigen::Quaterniond yaw_quaternion(double yaw);
double yaw_of(const Eigen::Quaterniond& q);
inline double published_yaw(double yaw) { return yaw_of(yaw_quaternion(yaw)); }

// tf2_msgs/msg/TFMessage.
struct Transform {
  int64_t stamp_ns = 0;
  std::string parent, child;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};
Transform make_transform(int64_t stamp_ns, const std::string& parent, const std::string& child,
                         const Eigen::Isometry3d& pose);
Transform planar_transform(int64_t stamp_ns, const std::string& parent, const std::string& child, const Pose2d& pose);
Bytes encode_tf(const std::vector<Transform>& transforms);
std::vector<Transform> decode_tf(View cdr, const std::string& context);

// geometry_msgs/msg/PoseStamped: `pose` in frame `frame_id`. Decoded as a Transform with `parent` the
// frame and `child` empty.
Bytes encode_pose_stamped(int64_t stamp_ns, const std::string& frame_id, const Eigen::Isometry3d& pose);
Transform decode_pose_stamped(View cdr, const std::string& context);

// lidarloop_msgs/msg/ActorArray.
struct ActorState {
  std::string name, type;
  Pose2d pose;
};
Bytes encode_actor_array(int64_t stamp_ns, const std::vector<ActorState>& actors, const std::string& frame_id);
std::vector<ActorState> decode_actor_array(View cdr, const std::string& context, int64_t* stamp_ns = nullptr);

// diagnostic_msgs/msg/DiagnosticArray: the standard report of a component's health (what rqt_robot_monitor
// and Foxglove's diagnostics panel show), one DiagnosticStatus per component, each with KeyValue pairs.
enum DiagnosticLevel : uint8_t { kDiagnosticOk = 0, kDiagnosticWarn = 1, kDiagnosticError = 2, kDiagnosticStale = 3 };
struct DiagnosticStatus {
  uint8_t level = kDiagnosticOk;
  std::string name, message, hardware_id;
  std::vector<std::pair<std::string, std::string>> values;  // diagnostic_msgs/msg/KeyValue: key, value
};
struct DiagnosticArray {
  int64_t stamp_ns = 0;
  std::string frame_id;
  std::vector<DiagnosticStatus> status;
};
Bytes encode_diagnostic_array(const DiagnosticArray& array);
DiagnosticArray decode_diagnostic_array(View cdr, const std::string& context);

// velodyne_msgs/msg/VelodyneScan (ROS 2 velodyne driver): one revolution's raw UDP data packets, each
// velodyne_msgs/msg/VelodynePacket {builtin_interfaces/Time stamp, uint8[1206] data}.
inline constexpr size_t kVelodynePacketSize = 1206;
struct VelodynePacket {
  int64_t stamp_ns = 0;
  std::array<uint8_t, kVelodynePacketSize> data{};
};
struct VelodyneScan {
  int64_t stamp_ns = 0;
  std::string frame_id;
  std::vector<VelodynePacket> packets;
};
Bytes encode_velodyne_scan(const VelodyneScan& scan);
VelodyneScan decode_velodyne_scan(View cdr, const std::string& context);

}  // namespace lidarloop::ros2
