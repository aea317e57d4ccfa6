#include "logs/log_export.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include "common/input_error.hpp"
#include "logs/hdl32e_packets.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/pcap_file.hpp"
#include "logs/pcd_file.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/scan_messages.hpp"
#include "logs/tum_file.hpp"

namespace lidarloop {

namespace {

std::string context(const McapReader& reader, const McapMessage& m) {
  return reader.path() + ": message " + std::to_string(m.sequence) + " on " + m.channel->topic;
}

bool has_type(const McapMessage& m, const char* type) { return m.schema && m.schema->name == type; }

std::ofstream open_out(const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot write file (" + std::strerror(errno) + ")");
  return out;
}

void make_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create folder (" + ec.message() + ")");
}

std::string topic_list(const McapReader& reader) {
  std::string out;
  for (const auto& [id, c] : reader.channels()) out += (out.empty() ? "" : ", ") + c.topic;
  return out.empty() ? "none" : out;
}

[[noreturn]] void nothing_on(const McapReader& reader, const std::string& topic, const char* what) {
  throw InputError(reader.path() + ": no " + what + " on topic '" + topic + "' (topics: " + topic_list(reader) + ")");
}

std::string numbered(const std::string& dir, size_t index, int digits, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof name, "%0*zu%s", digits, index, ext);
  return dir + "/" + name;
}

void put_le32(std::vector<char>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char(v >> (8 * i)));
}

}  // namespace

std::string kitti_timestamp(int64_t ns) {
  const ros2::Stamp s = ros2::to_stamp(ns);
  const std::time_t sec = s.sec;
  std::tm tm{};
  gmtime_r(&sec, &tm);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d.%09u", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, s.nanosec);
  return text;
}

ExportResult export_tum(const std::string& log, const std::string& file, const std::string& topic) {
  McapReader reader(log);
  std::map<std::string, std::vector<ros2::Odometry>> poses;  // by topic
  for (McapMessage m; reader.next(m);) {
    if (!has_type(m, "nav_msgs/msg/Odometry")) continue;
    if (!topic.empty() && m.channel->topic != topic) continue;
    poses[m.channel->topic].push_back(ros2::decode_odometry(m.data, context(reader, m)));
  }
  std::string chosen = topic;
  if (chosen.empty()) chosen = poses.count(log_topics::estimate) ? log_topics::estimate : log_topics::truth_odometry;
  if (!poses.count(chosen)) nothing_on(reader, chosen, "nav_msgs/msg/Odometry messages");

  // Exact: the stamp in integer nanoseconds and every number read back as the same double, so a
  // trajectory exported here and scored (`lidarloop score`) is the log's to the last bit.
  std::ofstream out = open_out(file);
  out << kTumHeader;
  for (const auto& o : poses[chosen]) out << tum_line({o.stamp_ns, o.position, o.orientation}) << '\n';
  if (!out.flush()) throw InputError(file + ": write failed");
  return {chosen, poses[chosen].size()};
}

ExportResult export_pcd(const std::string& log, const std::string& dir, const Hdl32eCalibration& calibration,
                        const std::string& topic) {
  McapReader reader(log);
  make_dir(dir);
  std::ofstream stamps = open_out(dir + "/timestamps.txt");
  size_t count = 0;
  std::vector<char> body;
  std::string chosen = topic.empty() ? log_topics::scan : topic;
  for (McapMessage m; reader.next(m);) {
    const std::optional<PointCloud> scan = scan_message(reader, m, calibration, topic);
    if (!scan) continue;
    chosen = m.channel->topic;
    const PointCloud& cloud = *scan;
    const std::string h =
        binary_pcd_header({{"x"}, {"y"}, {"z"}, {"intensity"}, {"ring", 2, 'U'}, {"time"}}, cloud.points.size(),
                          "lidarloop scan, stamp " + std::to_string(cloud.stamp_ns) + " ns");
    body.clear();
    body.reserve(cloud.points.size() * 22);
    for (const LidarPoint& p : cloud.points) {
      for (float v : {p.x, p.y, p.z, float(p.intensity)}) put_le32(body, std::bit_cast<uint32_t>(v));
      body.push_back(char(p.ring));
      body.push_back(char(p.ring >> 8));
      put_le32(body, std::bit_cast<uint32_t>(float(double(p.t_ns) * 1e-9)));
    }
    const std::string path = numbered(dir, count, 6, ".pcd");
    std::ofstream out = open_out(path);
    out.write(h.data(), std::streamsize(h.size()));
    out.write(body.data(), std::streamsize(body.size()));
    if (!out.flush()) throw InputError(path + ": write failed");
    stamps << cloud.stamp_ns << "\n";
    ++count;
  }
  if (count == 0) nothing_on(reader, chosen, "scans");
  return {chosen, count};
}

ExportResult export_kitti(const std::string& log, const std::string& dir, const Hdl32eCalibration& calibration,
                          const std::string& topic) {
  std::string chosen = topic.empty() ? log_topics::scan : topic;
  McapReader reader(log);
  const std::string velo = dir + "/velodyne_points", oxts = dir + "/oxts";
  make_dir(velo + "/data");
  make_dir(oxts + "/data");
  std::ofstream velo_mid = open_out(velo + "/timestamps.txt"), velo_start = open_out(velo + "/timestamps_start.txt"),
                velo_end = open_out(velo + "/timestamps_end.txt");

  // OXTS packets from the RTK stream when there is one (KITTI's are from an RTK GNSS/INS), else the
  // low-cost GPS; speed and yaw rate from the latest ground truth.
  struct Fix {
    GpsFix fix;
    double heading = 0, speed = 0, yaw_rate = 0;
  };
  std::map<std::string, std::vector<Fix>> fixes;  // by topic
  std::map<std::string, ros2::GnssHeading> headings;
  std::optional<TruthSample> truth;
  std::optional<ros2::Transform> mount;
  size_t scans = 0;
  std::vector<char> body;
  for (McapMessage m; reader.next(m);) {
    const std::string& t = m.channel->topic;
    if (const std::optional<PointCloud> scan = scan_message(reader, m, calibration, topic)) {
      chosen = t;
      const PointCloud& cloud = *scan;
      body.clear();
      body.reserve(cloud.points.size() * 16);
      uint32_t last = 0;
      for (const LidarPoint& p : cloud.points) {
        for (float v : {p.x, p.y, p.z, float(p.intensity) / 255.0f}) put_le32(body, std::bit_cast<uint32_t>(v));
        last = std::max(last, p.t_ns);
      }
      const std::string path = numbered(velo + "/data", scans, 10, ".bin");
      std::ofstream out = open_out(path);
      out.write(body.data(), std::streamsize(body.size()));
      if (!out.flush()) throw InputError(path + ": write failed");
      velo_start << kitti_timestamp(cloud.stamp_ns) << "\n";
      velo_end << kitti_timestamp(cloud.stamp_ns + last) << "\n";
      velo_mid << kitti_timestamp(cloud.stamp_ns + last / 2) << "\n";
      ++scans;
    } else if (has_type(m, "sensor_msgs/msg/NavSatFix")) {
      Fix f{ros2::decode_nav_sat_fix(m.data, context(reader, m))};
      if (truth) {
        f.speed = truth->speed;
        f.yaw_rate = truth->yaw_rate;
      }
      fixes[t].push_back(f);
    } else if (has_type(m, "lidarloop_msgs/msg/GnssHeading")) {
      const auto h = ros2::decode_gnss_heading(m.data, context(reader, m));
      // The heading follows its fix on the same receiver's topic: /gps/fix -> /gps/heading.
      const std::string fix_topic = t.substr(0, t.rfind('/')) + "/fix";
      if (auto it = fixes.find(fix_topic);
          it != fixes.end() && !it->second.empty() && it->second.back().fix.stamp_ns == h.stamp_ns)
        it->second.back().heading = h.heading;
    } else if (t == log_topics::truth_state && has_type(m, "lidarloop_msgs/msg/TruthState")) {
      truth = ros2::decode_truth_state(m.data, context(reader, m));
    } else if (t == log_topics::tf_static && has_type(m, "tf2_msgs/msg/TFMessage")) {
      for (const auto& tr : ros2::decode_tf(m.data, context(reader, m)))
        if (tr.child == log_topics::lidar_frame) mount = tr;
    }
  }
  if (scans == 0) nothing_on(reader, chosen, "scans");

  const std::string gnss = fixes.count(log_topics::rtk_fix) ? log_topics::rtk_fix : log_topics::gps_fix;
  std::ofstream oxts_stamps = open_out(oxts + "/timestamps.txt");
  size_t n = 0;
  for (const Fix& f : fixes[gnss]) {
    std::ofstream out = open_out(numbered(oxts + "/data", n++, 10, ".txt"));
    const double vf = f.speed, ve = vf * std::cos(f.heading), vn = vf * std::sin(f.heading);
    const double accuracy = std::sqrt(std::max(0.0, f.fix.position_covariance[0] + f.fix.position_covariance[4]));
    out.precision(12);
    // lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz wf wl wu
    // pos_accuracy vel_accuracy navstat numsats posmode velmode orimode
    out << f.fix.lat_deg << ' ' << f.fix.lon_deg << ' ' << f.fix.alt_m << " 0 0 " << f.heading << ' ' << vn << ' ' << ve
        << ' ' << vf << " 0 0 0 0 0 0 0 0 0 0 " << f.yaw_rate << " 0 0 " << f.yaw_rate << ' ' << accuracy << " 0 "
        << (f.fix.status == GpsStatus::no_fix ? 0 : 4) << " 0 " << (f.fix.status == GpsStatus::rtk ? 5 : 2) << " 0 0\n";
    oxts_stamps << kitti_timestamp(f.fix.stamp_ns) << "\n";
  }
  std::ofstream format = open_out(oxts + "/dataformat.txt");
  format << "lat:   latitude of the oxts-unit (deg)\nlon:   longitude of the oxts-unit (deg)\n"
            "alt:   altitude of the oxts-unit (m)\nroll:  roll angle (rad), 0 (planar simulation)\n"
            "pitch: pitch angle (rad), 0 (planar simulation)\n"
            "yaw:   heading (rad), 0 = east, positive = counter clockwise\n"
            "vn, ve: velocity towards north, east (m/s), from ground-truth speed and the GNSS heading\n"
            "vf:    forward velocity (m/s), ground truth\nvl, vu: 0\nax ay az af al au: 0 (not simulated)\n"
            "wx, wy: 0\nwz, wu: yaw rate (rad/s), ground truth\nwf, wl: 0\n"
            "pos_accuracy: position accuracy (m), from the fix covariance\nvel_accuracy: 0\n"
            "navstat: 4 with a fix, 0 without\nnumsats: 0 (not simulated)\n"
            "posmode: 5 RTK, 2 single-point\nvelmode, orimode: 0\n"
            "source: "
         << gnss << "\n";

  if (mount) {
    // KITTI's calib_imu_to_velo maps IMU coordinates into the LiDAR frame: the inverse of the mount.
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = mount->rotation.toRotationMatrix();
    pose.translation() = mount->translation;
    const Eigen::Isometry3d imu_to_velo = pose.inverse();
    std::ofstream calib = open_out(dir + "/calib_imu_to_velo.txt");
    calib.precision(9);
    calib << "calib_time: lidarloop (vehicle frame base_link taken as the IMU frame)\nR:";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) calib << ' ' << imu_to_velo.linear()(r, c);
    calib << "\nT:";
    for (int r = 0; r < 3; ++r) calib << ' ' << imu_to_velo.translation()(r) + 0.0;  // no "-0"
    calib << "\n";
  }
  return {chosen, scans};
}

ExportResult export_pcap(const std::string& log, const std::string& file, const std::string& topic) {
  const std::string chosen = topic.empty() ? log_topics::velodyne_packets : topic;
  constexpr const char* kScanType = "velodyne_msgs/msg/VelodyneScan";
  constexpr int64_t kNsPerS = 1'000'000'000;
  // The sensor's factory address (the HDL-32E manual's default 192.168.1.201) and Velodyne's MAC
  // prefix 60:76:88; it broadcasts (255.255.255.255), so any host on the link receives the capture.
  const UdpEndpoints endpoints{{0x60, 0x76, 0x88, 0x00, 0x00, 0x01}, {192, 168, 1, 201}, {255, 255, 255, 255}};

  // First pass: the GPS fixes with their headings, the ground-truth speed, and whether there are scans.
  struct Fix {
    GpsFix fix;
    double speed = 0;
  };
  std::vector<Fix> fixes;
  double speed = 0;
  size_t scans = 0;
  {
    McapReader reader(log);
    for (McapMessage m; reader.next(m);) {
      const std::string& t = m.channel->topic;
      if (t == chosen && has_type(m, kScanType)) {
        ++scans;
      } else if (t == log_topics::gps_fix && has_type(m, "sensor_msgs/msg/NavSatFix")) {
        fixes.push_back({ros2::decode_nav_sat_fix(m.data, context(reader, m)), speed});
      } else if (t == log_topics::gps_heading && has_type(m, "lidarloop_msgs/msg/GnssHeading")) {
        const auto h = ros2::decode_gnss_heading(m.data, context(reader, m));
        if (!fixes.empty() && fixes.back().fix.stamp_ns == h.stamp_ns) fixes.back().fix.heading_rad = h.heading;
      } else if (t == log_topics::truth_state && has_type(m, "lidarloop_msgs/msg/TruthState")) {
        speed = ros2::decode_truth_state(m.data, context(reader, m)).speed;
      }
    }
    if (scans == 0)
      throw InputError(log + ": no " + kScanType + " messages on topic '" + chosen +
                       "': record the run with --record FILE.mcap --packets");
  }

  // Second pass: the data packets in order, a position packet at each whole second on the way.
  McapReader reader(log);
  PcapWriter pcap(file, endpoints);
  size_t packets = 0, next_fix = 0;
  std::optional<int64_t> next_second;
  auto position_packets_until = [&](int64_t t_ns) {
    for (; *next_second <= t_ns; *next_second += kNsPerS) {
      while (next_fix < fixes.size() && fixes[next_fix].fix.stamp_ns <= *next_second) ++next_fix;
      const Fix none{};
      const Fix& f = next_fix > 0 ? fixes[next_fix - 1] : none;
      const std::string nmea = gprmc_sentence(*next_second, f.fix, f.speed);
      pcap.write_udp(*next_second, kHdl32ePositionPort, encode_hdl32e_position_packet(*next_second, nmea));
    }
  };
  for (McapMessage m; reader.next(m);) {
    if (m.channel->topic != chosen || !has_type(m, kScanType)) continue;
    const std::string where = context(reader, m);
    const ros2::VelodyneScan scan = ros2::decode_velodyne_scan(m.data, where);
    for (size_t i = 0; i < scan.packets.size(); ++i) {
      const ros2::VelodynePacket& p = scan.packets[i];
      decode_hdl32e_packet(p.data, where + ", packet " + std::to_string(i));  // an HDL-32E packet, or stop
      if (!next_second) next_second = (p.stamp_ns + kNsPerS - 1) / kNsPerS * kNsPerS;
      position_packets_until(p.stamp_ns);
      pcap.write_udp(p.stamp_ns, kHdl32eDataPort, p.data);
      ++packets;
    }
  }
  pcap.close();
  return {chosen, packets};
}

}  // namespace lidarloop
