#pragma once
// Records a run as an MCAP log a ROS 2 / Foxglove user can open: every sensor stream, the ground
// truth, the localizer's estimate, and the run's scenario and settings as an attachment and metadata.
// Topics, types and frames are listed in log_topics.hpp. It knows messages, not where they come from:
// the simulator's streams reach it through an adapter in loop/ (run_recording.hpp).
//
// Channels are registered when their first message arrives, so a log holds only the streams the run
// produced. The same calls in the same order give the same bytes (see McapWriter).
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "common/hdl32e_block.hpp"
#include "common/point_cloud.hpp"
#include "common/vehicle_messages.hpp"
#include "logs/localizer_status.hpp"
#include "logs/mcap/mcap_writer.hpp"
#include "logs/ros2_messages.hpp"

namespace lidarloop {

class McapRecorder {
 public:
  // `lidar_mount`: the LiDAR's pose in the vehicle frame; `gps_antenna`: the GPS antenna's position in
  // the vehicle frame (the lever arm from the rear axle; a fix is the antenna's position). Both are published
  // once on /tf_static (base_link -> lidar, base_link -> gps), so that a ROS user's tf and the fixes on
  // the gps frame agree. Give the configuration the localizer is given (the nominal extrinsics).
  McapRecorder(const std::string& path, const Eigen::Isometry3d& lidar_mount, const Eigen::Vector3d& gps_antenna,
               McapWriterOptions options = {});
  // The same messages into `sink` (a live stream to another program; see McapWriter), with a Metadata
  // record `metadata_name` first, so the reader has it before any message.
  McapRecorder(const std::string& name, McapOutput::ByteSink sink, const Eigen::Isometry3d& lidar_mount,
               const Eigen::Vector3d& gps_antenna, McapWriterOptions options, const std::string& metadata_name,
               const std::map<std::string, std::string>& metadata);

  void write_truth(const TruthSample& truth);
  void write_can(const CanFrame& frame);
  void write_gps(const GpsFix& fix);
  void write_rtk(const GpsFix& fix);
  void write_scan(const PointCloud& cloud);
  void write_actors(int64_t stamp_ns, const std::vector<ros2::ActorState>& actors);
  void write_curb_visibility(const CurbVisibility& visibility);
  // A scan as the HDL-32E's data packets (logs/hdl32e_packets.hpp, each on the sensor's clock), the
  // message stamped `stamp_ns` as its cloud is (by the host), so that a cloud decoded from it has the
  // live cloud's stamp.
  void write_velodyne_scan(const Hdl32eRotation& rotation, int64_t stamp_ns);

  // The localizer's answer to a scan: its status on /localizer/status (localizer_status.hpp), and
  // once it has a pose (`pose` set) /localizer/odometry (covariance of x, y, yaw) and /tf, all at the
  // status's stamp.
  void write_estimate(const LocalizerStatus& status, const std::optional<Pose2d>& pose,
                      const Eigen::Matrix3d& cov_xy_yaw);

  // Logged at the current log time (the newest stamp seen so far), never at wall-clock time.
  void add_attachment(const std::string& name, const std::string& media_type, std::span<const uint8_t> bytes);
  void add_attachment(const std::string& name, const std::string& media_type, std::string_view bytes);
  void add_metadata(const std::string& name, const std::map<std::string, std::string>& values);

  // Hands everything written so far to the file or sink.
  void flush() { writer_.flush(); }

  // Finishes the file (summary, footer). The destructor does it too, but swallows errors.
  void close();

  McapWriterStats stats() const { return writer_.stats(); }
  const std::string& path() const { return writer_.path(); }

 private:
  struct ChannelSpec {
    const char* topic;
    const char* type;
    bool latched = false;  // /tf_static: transient-local durability, as ROS 2 publishes it
  };
  void write_transforms(const Eigen::Isometry3d& lidar_mount, const Eigen::Vector3d& gps_antenna);
  void write(const ChannelSpec& spec, int64_t stamp_ns, const std::vector<uint8_t>& data);
  uint16_t channel(const ChannelSpec& spec);

  McapWriter writer_;
  std::map<std::string, uint16_t> schemas_, channels_;  // by type, by topic
  uint64_t clock_ = 0;                                  // log time: the newest stamp received
  std::vector<uint8_t> scan_buffer_;                    // a scan's CDR, reused from scan to scan
};

}  // namespace lidarloop
