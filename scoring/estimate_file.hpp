#pragma once
// Reading the trajectory a localizer under test produced, for `lidarloop score`:
//   TUM   "t x y z qx qy qz qw" a line (t in seconds; logs/tum_file.hpp), no covariance;
//   MCAP  one topic of nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped, CDR, as
//         a ROS 2 localizer recorded with rosbag2 writes it (header stamps, the (x, y, yaw) block of
//         the pose covariance).
// A lidarloop log's own /localizer/odometry comes with its /localizer/status (logs/localizer_status.hpp):
// each estimate's health, lost state and protection bounds are read from it, matched by stamp.
// The format is told by the content (the MCAP magic), not the file name. Poses are taken as in the
// map frame (the truth's); the yaw of a full 3-D quaternion is taken (ros2::yaw_of, the function the
// log's own readers use). Latency is not known from a file (NaN, written as null).
#include <string>
#include <vector>

#include "scoring/scorer.hpp"

namespace lidarloop {

struct EstimateFile {
  std::string format;               // "TUM" or "MCAP"
  std::string topic;                // MCAP: the topic read
  std::string type;                 // MCAP: its message type
  std::vector<std::string> frames;  // MCAP: the header frame_ids met (for a note when it is not "map")
  std::vector<EstimateRecord> estimates;
};

// True when the file starts with the MCAP magic.
bool is_mcap_file(const std::string& path);

// `topic` (MCAP only): the topic to read; empty picks the file's only Odometry or
// PoseWithCovarianceStamped topic. InputError naming `path` and the problem for a missing, empty or
// malformed file (a TUM line's number), stamps that do not increase, a non-finite value, a zero
// quaternion, a topic that is absent or of another type, or several candidate topics (listed).
EstimateFile read_estimate_file(const std::string& path, const std::string& topic = "");

}  // namespace lidarloop
