#pragma once
// Records a run as an MCAP log a ROS 2 / Foxglove user can open: every simulator stream (through
// the StreamSink interface), the localizer's estimate, and the run's scenario and settings as an
// attachment and metadata. Topics, types and frames are listed in log_topics.hpp.
//
// Channels are registered when their first message arrives, so a log holds only the streams the run
// produced. The same calls in the same order give the same bytes (see McapWriter).
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

#include "sim/simulation.hpp"
#include "tools/mcap/mcap_writer.hpp"

namespace lidarloop {

class McapRecorder : public StreamSink {
 public:
  // `lidar_mount`: the LiDAR's pose in the vehicle frame, published once on /tf_static.
  McapRecorder(const std::string& path, const Eigen::Isometry3d& lidar_mount, McapWriterOptions options = {});

  void on_truth(const TruthSample& truth) override;
  void on_can(const CanFrame& frame) override;
  void on_gps(const GpsFix& fix) override;
  void on_rtk(const GpsFix& fix) override;
  void on_scan(const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose) override;
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override;

  // The localizer's estimate: /localizer/odometry (covariance of x, y, yaw) and /tf.
  void write_estimate(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& cov_xy_yaw);

  // Logged at the current log time (the newest stamp seen so far), never at wall-clock time.
  void add_attachment(const std::string& name, const std::string& media_type, std::span<const uint8_t> bytes);
  void add_attachment(const std::string& name, const std::string& media_type, std::string_view bytes);
  void add_metadata(const std::string& name, const std::map<std::string, std::string>& values);

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
  void write(const ChannelSpec& spec, int64_t stamp_ns, const std::vector<uint8_t>& data);
  uint16_t channel(const ChannelSpec& spec);

  McapWriter writer_;
  std::map<std::string, uint16_t> schemas_, channels_;  // by type, by topic
  uint64_t clock_ = 0;  // log time: the newest stamp received
  std::vector<uint8_t> scan_buffer_;  // a scan's CDR, reused from scan to scan
};

}  // namespace lidarloop
