#include "scoring/estimate_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "common/input_error.hpp"
#include "logs/localizer_status.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/tum_file.hpp"
#include "scoring/result_files.hpp"

namespace lidarloop {

namespace {

constexpr const char* kOdometry = "nav_msgs/msg/Odometry";
constexpr const char* kPoseWithCovariance = "geometry_msgs/msg/PoseWithCovarianceStamped";
constexpr double kMinQuaternionNorm = 1e-6;  // as a TUM line's (logs/tum_file.cpp)

// "nav_msgs/Odometry" (ROS 1 style, some writers) and "nav_msgs/msg/Odometry" alike.
std::string full_type(const std::string& name) {
  const size_t slash = name.find('/');
  if (slash == std::string::npos || name.find("/msg/") != std::string::npos) return name;
  return name.substr(0, slash) + "/msg" + name.substr(slash);
}

EstimateRecord record(int64_t stamp_ns, const Eigen::Vector3d& position, const Eigen::Quaterniond& q,
                      const Eigen::Matrix3d& covariance) {
  EstimateRecord e;
  e.stamp_ns = stamp_ns;
  e.pose = {position.x(), position.y(), ros2::yaw_of(q)};
  e.covariance = covariance;
  return e;
}

EstimateFile read_tum_file(const std::string& path) {
  const std::optional<std::string> text = read_text_file(path);
  if (!text) throw InputError(path + ": cannot open file");
  EstimateFile out;
  out.format = "TUM";
  for (const TumPose& p : parse_tum(*text, path))
    out.estimates.push_back(record(p.stamp_ns, p.position, p.orientation, Eigen::Matrix3d::Zero()));
  return out;
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "none" : out;
}

// A lidarloop log's /localizer/status says of each of its /localizer/odometry estimates whether the
// localizer was lost and what it bounded the error by (logs/localizer_status.hpp), matched by stamp.
// An estimate without a status (an older log) keeps them unknown.
void apply_statuses(std::vector<EstimateRecord>& estimates, const std::map<int64_t, LocalizerStatus>& statuses) {
  for (EstimateRecord& e : estimates) {
    const auto s = statuses.find(e.stamp_ns);
    if (s == statuses.end()) continue;
    e.status = s->second.health;
    e.lost = s->second.lost;
    e.protection_lateral_m = s->second.protection_lateral_m;
    e.protection_longitudinal_m = s->second.protection_longitudinal_m;
    if (s->second.mount_yaw_deg) e.mount_yaw_deg = *s->second.mount_yaw_deg;
    if (s->second.mount_yaw_sigma_deg) e.mount_yaw_sigma_deg = *s->second.mount_yaw_sigma_deg;
  }
}

EstimateFile read_mcap_file(const std::string& path, const std::string& wanted) {
  McapReader reader(path);
  std::map<std::string, EstimateFile> by_topic;   // every candidate topic, or only the wanted one
  std::map<std::string, std::string> candidates;  // topic -> type, of every candidate channel
  std::map<int64_t, LocalizerStatus> statuses;    // by stamp
  size_t status_messages = 0;
  for (McapMessage m; reader.next(m);) {
    if (m.channel->topic == log_topics::localizer_status) {
      const std::string where =
          path + ": message " + std::to_string(++status_messages) + " on " + log_topics::localizer_status;
      if (auto s = decode_localizer_status(m.data, where)) statuses[s->stamp_ns] = std::move(*s);
      continue;
    }
    const std::string type = m.schema ? full_type(m.schema->name) : "";
    if (type != kOdometry && type != kPoseWithCovariance) continue;
    const std::string& topic = m.channel->topic;
    candidates[topic] = type;
    if (!wanted.empty() && topic != wanted) continue;
    EstimateFile& file = by_topic[topic];
    const std::string where = path + ": message " + std::to_string(file.estimates.size() + 1) + " on " + topic;
    if (m.channel->message_encoding != "cdr")
      throw InputError(where + ": message encoding '" + m.channel->message_encoding + "', expected cdr");
    const ros2::Odometry o = type == kOdometry ? ros2::decode_odometry(m.data, where)
                                               : ros2::decode_pose_with_covariance_stamped(m.data, where);
    file.type = type;
    if (std::find(file.frames.begin(), file.frames.end(), o.frame_id) == file.frames.end())
      file.frames.push_back(o.frame_id);
    const Eigen::Matrix3d cov = ros2::planar_covariance(o.pose_covariance);
    if (!o.position.allFinite() || !o.orientation.coeffs().allFinite() || !cov.allFinite())
      throw InputError(where + ": a pose or covariance value is not finite");
    if (!(o.orientation.norm() >= kMinQuaternionNorm)) throw InputError(where + ": the quaternion is zero");
    if (!file.estimates.empty() && o.stamp_ns <= file.estimates.back().stamp_ns)
      throw InputError(where + ": header stamp " + tum_seconds(o.stamp_ns) + " s is not after the previous one's " +
                       tum_seconds(file.estimates.back().stamp_ns) + " s (stamps must increase)");
    file.estimates.push_back(record(o.stamp_ns, o.position, o.orientation, cov));
  }
  std::vector<std::string> listed;
  for (const auto& [topic, type] : candidates) listed.push_back(topic + " (" + type + ")");
  std::string topic = wanted;
  if (topic.empty()) {
    if (candidates.size() != 1)
      throw InputError(path + ": " + (candidates.empty() ? "no" : "several") +
                       " nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped topics (" +
                       joined(listed) + "); name one with --topic");
    topic = candidates.begin()->first;
  }
  if (!candidates.count(topic)) {
    std::vector<std::string> all;
    for (const auto& [id, c] : reader.channels()) all.push_back(c.topic);
    throw InputError(path + ": no nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped on topic '" +
                     topic + "' (topics: " + joined(all) + ")");
  }
  if (!by_topic.count(topic)) throw InputError(path + ": no messages on topic '" + topic + "'");
  EstimateFile out = std::move(by_topic.at(topic));
  if (topic == log_topics::estimate) apply_statuses(out.estimates, statuses);
  out.format = "MCAP";
  out.topic = topic;
  return out;
}

}  // namespace

bool is_mcap_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  in.read(head, sizeof head);
  return in.gcount() == sizeof head &&
         std::equal(head, head + sizeof head, mcap::kMagic.begin(), [](char a, uint8_t b) { return uint8_t(a) == b; });
}

EstimateFile read_estimate_file(const std::string& path, const std::string& topic) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path + ": is a folder, not a file (a rosbag2 bag? give the .mcap file inside it)");
  if (is_mcap_file(path)) return read_mcap_file(path, topic);
  if (!topic.empty()) throw InputError(path + ": --topic applies to an MCAP estimate, and this is not one (TUM)");
  return read_tum_file(path);
}

}  // namespace lidarloop
