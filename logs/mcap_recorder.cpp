#include "logs/mcap_recorder.hpp"

#include <algorithm>

#include "logs/hdl32e_packets.hpp"
#include "logs/log_topics.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/ros2_schemas.hpp"

namespace lidarloop {

namespace {

namespace t = log_topics;

// rosbag2's record of the publisher's QoS (the ROS 2 profile asks for it): "system default" for
// sensor streams, transient-local durability for /tf_static so late subscribers get it on playback.
std::string qos_profile(bool latched) {
  const std::string infinite = "    sec: 9223372036\n    nsec: 854775807\n";
  return std::string("- history: 3\n  depth: 0\n  reliability: 1\n  durability: ") + (latched ? "1" : "2") +
         "\n  deadline:\n" + infinite + "  lifespan:\n" + infinite + "  liveliness: 1\n" +
         "  liveliness_lease_duration:\n" + infinite + "  avoid_ros_namespace_conventions: false\n";
}

}  // namespace

McapRecorder::McapRecorder(const std::string& path, const Eigen::Isometry3d& lidar_mount,
                           const Eigen::Vector3d& gps_antenna, McapWriterOptions options)
    : writer_(path, std::move(options)) {
  write_transforms(lidar_mount, gps_antenna);
}

McapRecorder::McapRecorder(const std::string& name, McapOutput::ByteSink sink, const Eigen::Isometry3d& lidar_mount,
                           const Eigen::Vector3d& gps_antenna, McapWriterOptions options,
                           const std::string& metadata_name, const std::map<std::string, std::string>& metadata)
    : writer_(name, std::move(sink), std::move(options)) {
  writer_.add_metadata(metadata_name, metadata);
  write_transforms(lidar_mount, gps_antenna);
}

void McapRecorder::write_transforms(const Eigen::Isometry3d& lidar_mount, const Eigen::Vector3d& gps_antenna) {
  static constexpr ChannelSpec tf_static{t::tf_static, "tf2_msgs/msg/TFMessage", true};
  // The antenna is a point: its frame is base_link's, moved to it (a fix has no orientation).
  Eigen::Isometry3d antenna = Eigen::Isometry3d::Identity();
  antenna.translation() = gps_antenna;
  write(tf_static, 0,
        ros2::encode_tf({ros2::make_transform(0, t::vehicle_frame, t::lidar_frame, lidar_mount),
                         ros2::make_transform(0, t::vehicle_frame, t::gps_frame, antenna)}));
}

uint16_t McapRecorder::channel(const ChannelSpec& spec) {
  if (auto it = channels_.find(spec.topic); it != channels_.end()) return it->second;
  auto schema = schemas_.find(spec.type);
  if (schema == schemas_.end())
    schema = schemas_.emplace(spec.type, writer_.add_schema(spec.type, "ros2msg", ros2::schema_text(spec.type))).first;
  const uint16_t id =
      writer_.add_channel(schema->second, spec.topic, "cdr", {{"offered_qos_profiles", qos_profile(spec.latched)}});
  channels_.emplace(spec.topic, id);
  return id;
}

void McapRecorder::write(const ChannelSpec& spec, int64_t stamp_ns, const std::vector<uint8_t>& data) {
  // Streams arrive in simulation order, but a scan is stamped with its first firing and delivered
  // after its last; log time is the arrival, publish time the stamp.
  const uint64_t stamp = uint64_t(std::max<int64_t>(stamp_ns, 0));
  clock_ = std::max(clock_, stamp);
  writer_.write_message(channel(spec), clock_, stamp, data);
}

void McapRecorder::write_truth(const TruthSample& truth) {
  static constexpr ChannelSpec state{t::truth_state, "lidarloop_msgs/msg/TruthState"};
  static constexpr ChannelSpec odometry{t::truth_odometry, "nav_msgs/msg/Odometry"};
  static constexpr ChannelSpec tf{t::tf, "tf2_msgs/msg/TFMessage"};
  static constexpr ChannelSpec body{t::truth_body, "geometry_msgs/msg/PoseStamped"};
  write(state, truth.stamp_ns, ros2::encode_truth_state(truth));
  ros2::Odometry odom =
      ros2::planar_odometry(truth.stamp_ns, truth.pose, Eigen::Matrix3d::Zero(), t::map_frame, t::vehicle_frame);
  odom.linear.x() = truth.speed;
  odom.angular.z() = truth.yaw_rate;
  write(odometry, truth.stamp_ns, ros2::encode_odometry(odom));
  write(tf, truth.stamp_ns,
        ros2::encode_tf({ros2::planar_transform(truth.stamp_ns, t::map_frame, t::vehicle_frame, truth.pose)}));
  write(body, truth.stamp_ns, ros2::encode_pose_stamped(truth.stamp_ns, t::vehicle_frame, truth.body.pose()));
}

void McapRecorder::write_can(const CanFrame& frame) {
  static constexpr ChannelSpec report{t::vehicle_report, "lidarloop_msgs/msg/VehicleReport"};
  write(report, frame.stamp_ns, ros2::encode_vehicle_report(frame, t::vehicle_frame));
}

void McapRecorder::write_gps(const GpsFix& fix) {
  static constexpr ChannelSpec nav{t::gps_fix, "sensor_msgs/msg/NavSatFix"};
  static constexpr ChannelSpec heading{t::gps_heading, "lidarloop_msgs/msg/GnssHeading"};
  write(nav, fix.stamp_ns, ros2::encode_nav_sat_fix(fix, t::gps_frame));
  write(heading, fix.stamp_ns, ros2::encode_gnss_heading(fix, t::gps_frame));
}

void McapRecorder::write_rtk(const GpsFix& fix) {
  static constexpr ChannelSpec nav{t::rtk_fix, "sensor_msgs/msg/NavSatFix"};
  static constexpr ChannelSpec heading{t::rtk_heading, "lidarloop_msgs/msg/GnssHeading"};
  write(nav, fix.stamp_ns, ros2::encode_nav_sat_fix(fix, t::gps_frame));
  write(heading, fix.stamp_ns, ros2::encode_gnss_heading(fix, t::gps_frame));
}

void McapRecorder::write_scan(const PointCloud& cloud) {
  // The sensor pose is not logged separately: /tf (truth) and /tf_static (mount) give it.
  static constexpr ChannelSpec points{t::scan, "sensor_msgs/msg/PointCloud2"};
  ros2::encode_point_cloud(cloud, t::lidar_frame, scan_buffer_);
  write(points, cloud.stamp_ns, scan_buffer_);
}

void McapRecorder::write_velodyne_scan(const Hdl32eRotation& rotation, int64_t stamp_ns) {
  static constexpr ChannelSpec spec{t::velodyne_packets, "velodyne_msgs/msg/VelodyneScan"};
  ros2::VelodyneScan scan{stamp_ns, t::lidar_frame, hdl32e_data_packets(rotation)};
  write(spec, scan.stamp_ns, ros2::encode_velodyne_scan(scan));
}

void McapRecorder::write_actors(int64_t stamp_ns, const std::vector<ros2::ActorState>& actors) {
  static constexpr ChannelSpec spec{t::truth_actors, "lidarloop_msgs/msg/ActorArray"};
  write(spec, stamp_ns, ros2::encode_actor_array(stamp_ns, actors, t::map_frame));
}

void McapRecorder::write_curb_visibility(const CurbVisibility& visibility) {
  static constexpr ChannelSpec spec{t::truth_curb_visibility, "lidarloop_msgs/msg/CurbVisibility"};
  write(spec, visibility.stamp_ns, ros2::encode_curb_visibility(visibility));
}

void McapRecorder::write_estimate(const LocalizerStatus& status, const std::optional<Pose2d>& pose,
                                  const Eigen::Matrix3d& cov_xy_yaw) {
  static constexpr ChannelSpec odometry{t::estimate, "nav_msgs/msg/Odometry"};
  static constexpr ChannelSpec tf{t::tf, "tf2_msgs/msg/TFMessage"};
  static constexpr ChannelSpec diagnostics{t::localizer_status, "diagnostic_msgs/msg/DiagnosticArray"};
  const int64_t stamp_ns = status.stamp_ns;
  if (pose) {
    write(odometry, stamp_ns,
          ros2::encode_odometry(ros2::planar_odometry(stamp_ns, *pose, cov_xy_yaw, t::map_frame, t::estimate_frame)));
    write(tf, stamp_ns, ros2::encode_tf({ros2::planar_transform(stamp_ns, t::map_frame, t::estimate_frame, *pose)}));
  }
  write(diagnostics, stamp_ns, encode_localizer_status(status));
}

void McapRecorder::add_attachment(const std::string& name, const std::string& media_type,
                                  std::span<const uint8_t> bytes) {
  writer_.add_attachment({clock_, clock_, name, media_type, std::vector<uint8_t>(bytes.begin(), bytes.end())});
}

void McapRecorder::add_attachment(const std::string& name, const std::string& media_type, std::string_view bytes) {
  add_attachment(name, media_type,
                 std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
}

void McapRecorder::add_metadata(const std::string& name, const std::map<std::string, std::string>& values) {
  writer_.add_metadata(name, values);
}

void McapRecorder::close() { writer_.close(); }

}  // namespace lidarloop
