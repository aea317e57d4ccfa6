#pragma once
// The topics of a lidarloop log (MCAP, ROS 2 profile), their message types and frames: the contract
// between the recorder and whatever reads a log back (replay, export, info, other people's tools).
//
//   topic                 type                              frame_id -> child
//   /lidar/points         sensor_msgs/msg/PointCloud2       lidar (layout in ros2_messages.hpp; not in a
//                                                           --packets-only log: scan_messages.hpp)
//   /gps/fix              sensor_msgs/msg/NavSatFix         gps   (low-cost receiver)
//   /gps/heading          lidarloop_msgs/msg/GnssHeading    gps
//   /gps/rtk/fix          sensor_msgs/msg/NavSatFix         gps   (RTK-grade reference)
//   /gps/rtk/heading      lidarloop_msgs/msg/GnssHeading    gps
//   /vehicle/report       lidarloop_msgs/msg/VehicleReport  base_link (CAN wheel speeds, steering)
//   /truth/odometry       nav_msgs/msg/Odometry             map -> base_link (speed, yaw rate as twist)
//   /truth/state          lidarloop_msgs/msg/TruthState     map (lossless: replay scores against it)
//   /truth/actors         lidarloop_msgs/msg/ActorArray     map
//   /truth/body           geometry_msgs/msg/PoseStamped     base_link (the sprung body's frame on its suspension)
//   /truth/curb_visibility lidarloop_msgs/msg/CurbVisibility map (the curb the traffic hid, per scan)
//   /localizer/odometry   nav_msgs/msg/Odometry             map -> base_link_estimate (with covariance)
//   /localizer/status     diagnostic_msgs/msg/DiagnosticArray base_link_estimate (health, lost, protection
//                                                           bounds; every scan: localizer_status.hpp)
//   /tf                   tf2_msgs/msg/TFMessage            map -> base_link (truth), map -> base_link_estimate
//   /tf_static            tf2_msgs/msg/TFMessage            base_link -> lidar (mount), base_link -> gps
//   /velodyne_packets     velodyne_msgs/msg/VelodyneScan    lidar (with --packets or --packets-only: the
//                                                           scans' raw HDL-32E packets, hdl32e_packets.hpp)
//
// Frames: map is the local transverse Mercator frame (x east, y north, z up); base_link is the
// vehicle frame (x forward, y left, z up, origin at the rear axle centre on the ground); gps is the
// antenna, whose position a fix is: base_link moved by the configured lever arm (GpsConfig::antenna_xyz,
// 0.9 m ahead and 1.5 m up by default). /truth/body is the pose, in base_link, of the body
// frame: the frame that coincides with base_link when the body rests on flat ground, and that pitches
// and rolls about the centre of mass and heaves with it (identity for a rigid body). The LiDAR is
// mounted on the body: its true pose is base_link * body * mount, with the mount from /tf_static.
// Header stamps are measurement times, except /vehicle/report's: a CAN frame is stamped when the host
// received it (the bus latency plus the host clock's jitter). A message's MCAP log_time is the
// largest stamp recorded so far (never earlier than the log time of the message before it), so
// replaying in log-time order gives exactly the order of the live run.
namespace lidarloop::log_topics {

inline constexpr const char* scan = "/lidar/points";
inline constexpr const char* gps_fix = "/gps/fix";
inline constexpr const char* gps_heading = "/gps/heading";
inline constexpr const char* rtk_fix = "/gps/rtk/fix";
inline constexpr const char* rtk_heading = "/gps/rtk/heading";
inline constexpr const char* vehicle_report = "/vehicle/report";
inline constexpr const char* truth_odometry = "/truth/odometry";
inline constexpr const char* truth_state = "/truth/state";
inline constexpr const char* truth_actors = "/truth/actors";
inline constexpr const char* truth_body = "/truth/body";
inline constexpr const char* truth_curb_visibility = "/truth/curb_visibility";
inline constexpr const char* estimate = "/localizer/odometry";
inline constexpr const char* localizer_status = "/localizer/status";
inline constexpr const char* tf = "/tf";
inline constexpr const char* tf_static = "/tf_static";
inline constexpr const char* velodyne_packets = "/velodyne_packets";

inline constexpr const char* map_frame = "map";
inline constexpr const char* vehicle_frame = "base_link";
inline constexpr const char* estimate_frame = "base_link_estimate";
inline constexpr const char* lidar_frame = "lidar";
inline constexpr const char* gps_frame = "gps";

}  // namespace lidarloop::log_topics
