// MCAP logs: the writer's format (chunks, indexes, summary, CRCs), exact round trips of every
// stream, byte-identical output, chunk closing by size and time, recovery of cut and corrupted
// files, and malformed input giving InputError rather than a crash.
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>

#include "common/crc32.hpp"
#include "common/input_error.hpp"
#include "logs/cdr.hpp"
#include "logs/localizer_status.hpp"
#include "logs/log_export.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/mcap/mcap_recover.hpp"
#include "logs/mcap/zstd_codec.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/ros2_schemas.hpp"
#include "logs/tum_file.hpp"
#include "mcap_fixture.hpp"

namespace lidarloop {
namespace {

namespace topics = log_topics;
using Bytes = std::vector<uint8_t>;

// Per process: CTest runs each test case in its own process, two at a time, and every process of this
// suite writes the synthetic log first; a shared folder let one truncate the file another was reading.
std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("lidarloop_test_mcap_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

Bytes read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

void write_file(const std::string& path, std::span<const uint8_t> bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// Every message of a log in file order, copied out of the reader.
struct Msg {
  std::string topic, schema;
  uint32_t sequence;
  uint64_t log_time, publish_time;
  Bytes data;
  bool operator==(const Msg&) const = default;
};

std::vector<Msg> read_all(const std::string& path) {
  McapReader reader(path);
  std::vector<Msg> out;
  for (McapMessage m; reader.next(m);)
    out.push_back({m.channel->topic, m.schema ? m.schema->name : "", m.sequence, m.log_time, m.publish_time,
                   Bytes(m.data.begin(), m.data.end())});
  return out;
}

// Decodes a message the way replay and export do, by its schema name.
void decode(const McapMessage& m) {
  const std::string& type = m.schema ? m.schema->name : "";
  if (type == "sensor_msgs/msg/PointCloud2")
    ros2::decode_point_cloud(m.data, "test");
  else if (type == "sensor_msgs/msg/NavSatFix")
    ros2::decode_nav_sat_fix(m.data, "test");
  else if (type == "lidarloop_msgs/msg/GnssHeading")
    ros2::decode_gnss_heading(m.data, "test");
  else if (type == "lidarloop_msgs/msg/VehicleReport")
    ros2::decode_vehicle_report(m.data, "test");
  else if (type == "lidarloop_msgs/msg/TruthState")
    ros2::decode_truth_state(m.data, "test");
  else if (type == "nav_msgs/msg/Odometry")
    ros2::decode_odometry(m.data, "test");
  else if (type == "tf2_msgs/msg/TFMessage")
    ros2::decode_tf(m.data, "test");
  else if (type == "geometry_msgs/msg/PoseStamped")
    ros2::decode_pose_stamped(m.data, "test");
  else if (type == "lidarloop_msgs/msg/ActorArray")
    ros2::decode_actor_array(m.data, "test");
}

class McapLog : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    run_ = new test::SyntheticRun(test::make_synthetic_run(2.55, 500, 11));
    path_ = new std::string(temp_path("synthetic.mcap"));
    McapWriterOptions options;
    options.chunk_size = 48 << 10;  // several chunks from a small log
    test::record_synthetic_run(*run_, *path_, options);
  }
  static void TearDownTestSuite() {
    delete run_;
    delete path_;
  }
  static test::SyntheticRun* run_;
  static std::string* path_;
};
test::SyntheticRun* McapLog::run_ = nullptr;
std::string* McapLog::path_ = nullptr;

TEST(Crc32, MatchesTheStandardCheckValue) {
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);
  Crc32 split;
  split.update("12345", 5);
  Crc32 resumed = Crc32::resume(split.value());
  resumed.update("6789", 4);
  EXPECT_EQ(resumed.value(), 0xCBF43926u);
}

TEST(Cdr, AlignsEachPrimitiveToItsSizeAfterTheHeader) {
  CdrWriter w;
  w.i32(1);
  w.u32(2);
  w.string("map");
  w.u8(7);
  w.f64(1.0);
  const Bytes expected = {0,   1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 4, 0, 0, 0, 'm',  'a',
                          'p', 0, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xF0, 0x3F};
  EXPECT_EQ(w.buffer(), expected);
  CdrReader r(w.buffer(), "test");
  EXPECT_EQ(r.i32(), 1);
  EXPECT_EQ(r.u32(), 2u);
  EXPECT_EQ(r.string(), "map");
  EXPECT_EQ(r.u8(), 7);
  EXPECT_EQ(r.f64(), 1.0);
  EXPECT_THROW(r.u8(), InputError);
}

TEST(Cdr, RejectsBigEndianAndOverlongSequences) {
  const Bytes big_endian = {0, 0, 0, 0, 0, 0, 0, 1};
  EXPECT_THROW(CdrReader(big_endian, "test"), InputError);
  CdrWriter w;
  w.u32(1'000'000);
  CdrReader r(w.buffer(), "test");
  EXPECT_THROW(r.sequence_length(1), InputError);
}

TEST(Ros2Schemas, NestedTypesFollowInRosbag2Form) {
  const std::string odom = ros2::schema_text("nav_msgs/msg/Odometry");
  const std::string sep = "\n" + std::string(80, '=') + "\nMSG: ";
  EXPECT_EQ(odom.rfind("std_msgs/Header header\nstring child_frame_id\n", 0), 0u);
  for (const char* dep : {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/PoseWithCovariance",
                          "geometry_msgs/Pose", "geometry_msgs/Point", "geometry_msgs/Quaternion",
                          "geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist", "geometry_msgs/Vector3"}) {
    const auto at = odom.find(sep + dep + "\n");
    ASSERT_NE(at, std::string::npos) << dep;
    EXPECT_EQ(odom.find(sep + dep + "\n", at + 1), std::string::npos) << dep << " defined twice";
  }
  EXPECT_NE(ros2::schema_text("sensor_msgs/msg/PointCloud2").find(sep + "sensor_msgs/PointField\n"), std::string::npos);
  for (const auto& type : ros2::known_types()) EXPECT_NO_THROW(ros2::schema_text(type)) << type;
  EXPECT_THROW(ros2::schema_text("nav_msgs/msg/Path"), std::invalid_argument);
}

TEST(Zstd, DecompressionChecksTheDeclaredSize) {
  Bytes data(100'000);
  for (size_t i = 0; i < data.size(); ++i) data[i] = uint8_t(i * 7 % 13);
  ZstdCompressor z(3);
  Bytes packed;
  z.compress(data, packed);
  EXPECT_EQ(zstd_decompress(packed, data.size(), "test"), data);
  EXPECT_THROW(zstd_decompress(packed, data.size() - 1, "test"), InputError);
  EXPECT_THROW(zstd_decompress(packed, data.size() + 1, "test"), InputError);
  EXPECT_THROW(zstd_decompress(packed, uint64_t(1) << 60, "test"), InputError);  // no huge allocation either
  EXPECT_THROW(zstd_decompress(std::span<const uint8_t>(packed).first(packed.size() / 2), data.size(), "test"),
               InputError);
  Bytes garbage = packed;
  for (size_t i = 4; i < garbage.size(); i += 3) garbage[i] ^= 0x5A;
  EXPECT_THROW(zstd_decompress(garbage, data.size(), "test"), InputError);
}

TEST(Ros2Messages, CurbVisibilityRoundTripsExactly) {
  const CurbVisibility v{123'456'789'012, 345, 67, 8};
  const ros2::Bytes bytes = ros2::encode_curb_visibility(v);
  const CurbVisibility back = ros2::decode_curb_visibility(bytes, "test");
  EXPECT_EQ(back.stamp_ns, v.stamp_ns);
  EXPECT_EQ(back.visible, 345);
  EXPECT_EQ(back.hidden, 67);
  EXPECT_EQ(back.blocked_by_world, 8);
  EXPECT_THROW(ros2::decode_curb_visibility(ros2::View(bytes.data(), bytes.size() - 1), "test"), InputError);
}

// /localizer/status as a DiagnosticArray: the values as text that reads back to the same bits, the
// wire layout of diagnostic_msgs, and a malformed value an InputError naming the message.
TEST(LocalizerStatus, RoundTripsExactlyAsADiagnosticArray) {
  LocalizerStatus s;
  s.stamp_ns = 8'100'000'000;
  s.level = ros2::kDiagnosticWarn;
  s.health = "no GPS, few curbs";
  s.health_flags = 0x41;
  s.protection_lateral_m = 0.1 + 0.2;  // 0.30000000000000004: needs all 17 digits
  s.protection_longitudinal_m = 1.0 / 3;
  const ros2::Bytes bytes = encode_localizer_status(s);
  const ros2::DiagnosticArray array = ros2::decode_diagnostic_array(bytes, "test");
  EXPECT_EQ(array.frame_id, topics::estimate_frame);
  ASSERT_EQ(array.status.size(), 1u);
  const ros2::DiagnosticStatus& d = array.status[0];
  EXPECT_EQ(d.level, 1);
  EXPECT_EQ(d.name, "lidarloop localizer");
  EXPECT_EQ(d.hardware_id, "lidarloop");
  EXPECT_EQ(d.message, "no GPS, few curbs");
  using KeyValues = std::vector<std::pair<std::string, std::string>>;
  EXPECT_EQ(d.values, (KeyValues{{"health_flags", "0x41"},
                                 {"lost", "false"},
                                 {"protection_lateral_m", "0.30000000000000004"},
                                 {"protection_longitudinal_m", "0.3333333333333333"},
                                 {"wide_search", "false"}}));
  const std::optional<LocalizerStatus> back = decode_localizer_status(bytes, "test");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->stamp_ns, s.stamp_ns);
  EXPECT_EQ(back->health_flags, 0x41u);
  EXPECT_EQ(back->protection_lateral_m, s.protection_lateral_m);
  EXPECT_EQ(back->protection_longitudinal_m, s.protection_longitudinal_m);

  LocalizerStatus lost;
  lost.level = ros2::kDiagnosticError;
  lost.lost = lost.wide_search = true;
  const ros2::Bytes lost_bytes = encode_localizer_status(lost);
  EXPECT_EQ(ros2::decode_diagnostic_array(lost_bytes, "test").status[0].values[2].second, "inf");
  const std::optional<LocalizerStatus> lost_back = decode_localizer_status(lost_bytes, "test");
  ASSERT_TRUE(lost_back.has_value());
  EXPECT_TRUE(lost_back->lost && lost_back->wide_search && std::isinf(lost_back->protection_longitudinal_m));

  // Another component's diagnostics are not the localizer's status; a malformed value is an error.
  ros2::DiagnosticArray other = array;
  other.status[0].name = "lidar driver";
  EXPECT_FALSE(decode_localizer_status(ros2::encode_diagnostic_array(other), "test").has_value());
  const std::vector<std::pair<size_t, std::string>> bad = {{0, "41"},   {0, "0x"},  {0, "4"}, {1, "yes"},
                                                           {2, "-0.5"}, {3, "1 m"}, {4, ""}};
  for (const auto& [index, value] : bad) {
    ros2::DiagnosticArray edited = array;
    edited.status[0].values[index].second = value;
    EXPECT_THROW(decode_localizer_status(ros2::encode_diagnostic_array(edited), "test"), InputError) << value;
  }
  ros2::DiagnosticArray missing = array;
  missing.status[0].values.pop_back();
  try {
    decode_localizer_status(ros2::encode_diagnostic_array(missing), "log.mcap");
    ADD_FAILURE() << "a status without wide_search was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("log.mcap: the localizer status has no value 'wide_search'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(decode_localizer_status(ros2::View(bytes.data(), bytes.size() - 3), "test"), InputError);
}

// A localizer that learns the LiDAR's mount yaw says so in two more values, which read back to the same
// bits; one without the other, or a value that is not a finite number, is an error. Without them the
// status is as it always was (above).
TEST(LocalizerStatus, CarriesALearntMountYawWhenThereIsOne) {
  LocalizerStatus s;
  s.mount_yaw_deg = 0.1 + 0.2;
  s.mount_yaw_sigma_deg = 1.0 / 3;
  const ros2::Bytes bytes = encode_localizer_status(s);
  const ros2::DiagnosticArray array = ros2::decode_diagnostic_array(bytes, "test");
  ASSERT_EQ(array.status.size(), 1u);
  const auto& values = array.status[0].values;
  ASSERT_EQ(values.size(), 7u);
  EXPECT_EQ(values[5], (std::pair<std::string, std::string>{"mount_yaw_deg", "0.30000000000000004"}));
  EXPECT_EQ(values[6], (std::pair<std::string, std::string>{"mount_yaw_sigma_deg", "0.3333333333333333"}));
  const std::optional<LocalizerStatus> back = decode_localizer_status(bytes, "test");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->mount_yaw_deg, s.mount_yaw_deg);
  EXPECT_EQ(back->mount_yaw_sigma_deg, s.mount_yaw_sigma_deg);
  for (const std::string& value : {"nan", "inf", "0.1 deg", ""}) {
    ros2::DiagnosticArray edited = array;
    edited.status[0].values[5].second = value;
    EXPECT_THROW(decode_localizer_status(ros2::encode_diagnostic_array(edited), "test"), InputError) << value;
  }
  ros2::DiagnosticArray half = array;
  half.status[0].values.pop_back();
  EXPECT_THROW(decode_localizer_status(ros2::encode_diagnostic_array(half), "test"), InputError);
}

TEST(Ros2Messages, PointCloudRoundTripsExactlyAndRejectsBadLayouts) {
  const auto run = test::make_synthetic_run(0.1, 300, 3);
  const PointCloud& cloud = run.scans.at(0);
  const Bytes cdr = ros2::encode_point_cloud(cloud, "lidar");
  const PointCloud back = ros2::decode_point_cloud(cdr, "test");
  EXPECT_EQ(back.stamp_ns, cloud.stamp_ns);
  ASSERT_EQ(back.points.size(), cloud.points.size());
  for (size_t i = 0; i < cloud.points.size(); ++i)
    EXPECT_TRUE(test::same_point(cloud.points[i], back.points[i])) << "point " << i;
  for (size_t cut : {size_t(3), size_t(40), cdr.size() / 2, cdr.size() - 2})
    EXPECT_THROW(ros2::decode_point_cloud(std::span<const uint8_t>(cdr).first(cut), "test"), InputError) << cut;
  EXPECT_EQ(ros2::to_stamp(-1).sec, -1);
  EXPECT_EQ(ros2::to_stamp(-1).nanosec, 999'999'999u);
  EXPECT_EQ(ros2::from_stamp(ros2::to_stamp(-1)), -1);
}

TEST_F(McapLog, EveryStreamRoundTripsExactly) {
  McapReader reader(*path_);
  EXPECT_EQ(reader.header().profile, "ros2");
  EXPECT_EQ(reader.header().library.rfind("lidarloop ", 0), 0u);
  std::vector<TruthSample> truth;
  std::vector<CanFrame> can;
  std::vector<GpsFix> gps, rtk;
  std::vector<ros2::GnssHeading> gps_heading, rtk_heading;
  std::vector<PointCloud> scans;
  std::vector<ros2::Odometry> estimates, truth_odometry;
  std::vector<std::optional<LocalizerStatus>> statuses;
  std::vector<std::vector<ros2::ActorState>> actors;
  std::vector<ros2::Transform> tf_static, bodies;
  size_t tf = 0;
  uint64_t last_log_time = 0;
  for (McapMessage m; reader.next(m);) {
    EXPECT_EQ(m.channel->message_encoding, "cdr");
    ASSERT_NE(m.schema, nullptr);
    EXPECT_EQ(m.schema->encoding, "ros2msg");
    EXPECT_GE(m.log_time, last_log_time) << "log times never go backwards";
    EXPECT_GE(m.log_time, m.publish_time);
    last_log_time = m.log_time;
    const std::string& t = m.channel->topic;
    if (t == topics::truth_state)
      truth.push_back(ros2::decode_truth_state(m.data, t));
    else if (t == topics::vehicle_report)
      can.push_back(ros2::decode_vehicle_report(m.data, t));
    else if (t == topics::gps_fix)
      gps.push_back(ros2::decode_nav_sat_fix(m.data, t));
    else if (t == topics::rtk_fix)
      rtk.push_back(ros2::decode_nav_sat_fix(m.data, t));
    else if (t == topics::gps_heading)
      gps_heading.push_back(ros2::decode_gnss_heading(m.data, t));
    else if (t == topics::rtk_heading)
      rtk_heading.push_back(ros2::decode_gnss_heading(m.data, t));
    else if (t == topics::scan)
      scans.push_back(ros2::decode_point_cloud(m.data, t));
    else if (t == topics::estimate)
      estimates.push_back(ros2::decode_odometry(m.data, t));
    else if (t == topics::truth_odometry)
      truth_odometry.push_back(ros2::decode_odometry(m.data, t));
    else if (t == topics::localizer_status)
      statuses.push_back(decode_localizer_status(m.data, t));
    else if (t == topics::truth_actors)
      actors.push_back(ros2::decode_actor_array(m.data, t));
    else if (t == topics::tf_static)
      tf_static = ros2::decode_tf(m.data, t);
    else if (t == topics::truth_body)
      bodies.push_back(ros2::decode_pose_stamped(m.data, t));
    else if (t == topics::tf)
      ++tf;
    else
      ADD_FAILURE() << "unexpected topic " << t;
  }
  const auto& run = *run_;
  ASSERT_EQ(truth.size(), run.truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    const auto &a = truth[i], &b = run.truth[i];
    EXPECT_TRUE(a.stamp_ns == b.stamp_ns && a.pose.x == b.pose.x && a.pose.y == b.pose.y && a.pose.yaw == b.pose.yaw &&
                a.speed == b.speed && a.yaw_rate == b.yaw_rate && a.steer == b.steer && a.cross_track == b.cross_track);
  }
  ASSERT_EQ(bodies.size(), run.truth.size());
  for (size_t i = 0; i < bodies.size(); ++i) {
    const Eigen::Isometry3d want = run.truth[i].body.pose();
    EXPECT_EQ(bodies[i].stamp_ns, run.truth[i].stamp_ns);
    EXPECT_EQ(bodies[i].parent, topics::vehicle_frame);
    EXPECT_TRUE(bodies[i].translation == want.translation());
    EXPECT_TRUE(bodies[i].rotation.coeffs() == Eigen::Quaterniond(want.rotation()).coeffs());
  }
  ASSERT_EQ(can.size(), run.can.size());
  for (size_t i = 0; i < can.size(); ++i)
    EXPECT_TRUE(can[i].stamp_ns == run.can[i].stamp_ns && can[i].wheel_speed_mps == run.can[i].wheel_speed_mps &&
                can[i].steering_wheel_angle_rad == run.can[i].steering_wheel_angle_rad);
  ASSERT_EQ(gps.size(), run.gps.size());
  ASSERT_EQ(rtk.size(), run.rtk.size());
  ASSERT_EQ(gps_heading.size(), run.gps.size());
  for (size_t i = 0; i < gps.size(); ++i) {
    for (const auto& [got, heading, want] :
         {std::tuple{gps[i], gps_heading[i], run.gps[i]}, std::tuple{rtk[i], rtk_heading[i], run.rtk[i]}}) {
      EXPECT_TRUE(got.stamp_ns == want.stamp_ns && got.status == want.status && got.lat_deg == want.lat_deg &&
                  got.lon_deg == want.lon_deg && got.alt_m == want.alt_m &&
                  got.position_covariance == want.position_covariance);
      EXPECT_TRUE(heading.stamp_ns == want.stamp_ns && heading.heading == want.heading_rad &&
                  heading.variance == want.heading_variance);
    }
  }
  ASSERT_EQ(scans.size(), run.scans.size());
  for (size_t s = 0; s < scans.size(); ++s) {
    EXPECT_EQ(scans[s].stamp_ns, run.scans[s].stamp_ns);
    ASSERT_EQ(scans[s].points.size(), run.scans[s].points.size());
    for (size_t i = 0; i < scans[s].points.size(); ++i) {
      const auto &a = scans[s].points[i], &b = run.scans[s].points[i];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.intensity == b.intensity && a.ring == b.ring &&
                  a.t_ns == b.t_ns)
          << "scan " << s << " point " << i;
    }
  }
  ASSERT_EQ(estimates.size(), run.estimates.size());
  for (size_t i = 0; i < estimates.size(); ++i) {
    const auto& o = estimates[i];
    const auto& e = run.estimates[i];
    EXPECT_EQ(o.stamp_ns, e.stamp_ns);
    EXPECT_EQ(o.frame_id, "map");
    EXPECT_EQ(o.child_frame_id, "base_link_estimate");
    EXPECT_EQ(o.position.x(), e.pose.x);
    EXPECT_EQ(o.position.y(), e.pose.y);
    EXPECT_NEAR(ros2::yaw_of(o.orientation), e.pose.yaw, 1e-12);
    const int k[3] = {0, 1, 5};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(o.pose_covariance[size_t(k[r] * 6 + k[c])], e.cov(r, c));
    EXPECT_EQ(o.pose_covariance[2 * 6 + 2], 0.0);
  }
  ASSERT_EQ(statuses.size(), run.estimates.size());
  for (size_t i = 0; i < statuses.size(); ++i) {
    ASSERT_TRUE(statuses[i].has_value()) << i;
    const LocalizerStatus &got = *statuses[i], &want = run.estimates[i].status;
    EXPECT_TRUE(got.stamp_ns == want.stamp_ns && got.level == want.level && got.health == want.health &&
                got.health_flags == want.health_flags && got.lost == want.lost &&
                got.protection_lateral_m == want.protection_lateral_m &&
                got.protection_longitudinal_m == want.protection_longitudinal_m && got.wide_search == want.wide_search)
        << "status " << i;
  }
  EXPECT_TRUE(std::isinf(statuses.at(2)->protection_lateral_m));  // lost: unbounded, and read back so
  ASSERT_EQ(truth_odometry.size(), run.truth.size());
  EXPECT_EQ(truth_odometry[3].linear.x(), run.truth[3].speed);
  EXPECT_EQ(truth_odometry[3].angular.z(), run.truth[3].yaw_rate);
  EXPECT_EQ(tf, run.truth.size() + run.estimates.size());
  ASSERT_EQ(tf_static.size(), 2u);
  EXPECT_EQ(tf_static[0].parent, "base_link");
  EXPECT_EQ(tf_static[0].child, "lidar");
  EXPECT_EQ(tf_static[0].translation, run.mount.translation());
  EXPECT_TRUE(tf_static[0].rotation.toRotationMatrix().isApprox(run.mount.linear(), 1e-15));
  // The antenna where the fixes are taken: the lever arm the recorder was given, unrotated.
  EXPECT_EQ(tf_static[1].parent, "base_link");
  EXPECT_EQ(tf_static[1].child, "gps");
  EXPECT_EQ(tf_static[1].translation, run.gps_antenna);
  EXPECT_TRUE(tf_static[1].rotation.isApprox(Eigen::Quaterniond::Identity(), 1e-15));
  ASSERT_EQ(actors.size(), run.actors.size());
  EXPECT_EQ(actors[1][0].name, "bus_1");
  EXPECT_EQ(actors[1][0].type, "bus");
  EXPECT_EQ(actors[1][1].type, "pedestrian");
  EXPECT_EQ(actors[1][1].pose.yaw, run.actors[1].second[1].pose.yaw);

  ASSERT_EQ(reader.attachments().size(), 1u);
  EXPECT_EQ(reader.attachments()[0].name, "scenario.yaml");
  EXPECT_EQ(std::string(reader.attachments()[0].data.begin(), reader.attachments()[0].data.end()), run.scenario_yaml);
  ASSERT_EQ(reader.metadata().size(), 1u);
  EXPECT_EQ(reader.metadata()[0].metadata.at("map_hash"), "0123abcd");
}

TEST_F(McapLog, SummaryAndIndexesDescribeTheData) {
  const auto summary = read_mcap_summary(*path_);
  ASSERT_TRUE(summary && summary->statistics);
  std::map<uint16_t, uint64_t> counts;
  McapReader reader(*path_);
  uint64_t messages = 0;
  for (McapMessage m; reader.next(m); ++messages) ++counts[m.channel->id];
  const auto& stats = *summary->statistics;
  EXPECT_EQ(stats.message_count, messages);
  EXPECT_EQ(stats.channel_message_counts, counts);
  EXPECT_EQ(stats.chunk_count, reader.chunks());
  EXPECT_GT(stats.chunk_count, 3u);
  EXPECT_EQ(summary->chunk_indexes.size(), stats.chunk_count);
  EXPECT_EQ(summary->channels.size(), reader.channels().size());
  EXPECT_EQ(summary->schemas.size(), reader.schemas().size());
  EXPECT_EQ(summary->attachment_indexes.size(), 1u);
  EXPECT_EQ(summary->metadata_indexes.size(), 1u);
  EXPECT_EQ(stats.schema_count, summary->schemas.size());

  // Every message index entry points at a message of its channel with its log time, and together
  // they cover every message of the chunk (what indexed readers such as Foxglove rely on).
  const Bytes file = read_file(*path_);
  for (const auto& ci : summary->chunk_indexes) {
    ByteReader chunk_in(std::span<const uint8_t>(file).subspan(ci.chunk_start_offset + 9, ci.chunk_length - 9),
                        "chunk");
    const mcap::Chunk chunk = mcap::parse_chunk(chunk_in);
    EXPECT_EQ(chunk.compression, "zstd");
    EXPECT_EQ(ci.compressed_size, chunk.records.size());
    EXPECT_LT(ci.message_end_time - ci.message_start_time, 1'000'000'000u);
    const Bytes records = chunk_records(chunk, "chunk");
    uint64_t indexed = 0, total_length = 0;
    for (const auto& [channel, offset] : ci.message_index_offsets) {
      ASSERT_EQ(file.at(offset), uint8_t(mcap::Op::message_index));
      uint64_t length = 0;
      for (int i = 0; i < 8; ++i) length |= uint64_t(file.at(offset + 1 + size_t(i))) << (8 * i);
      total_length += 9 + length;
      ByteReader index_in(std::span<const uint8_t>(file).subspan(offset + 9, length), "index");
      const mcap::MessageIndex index = mcap::parse_message_index(index_in);
      EXPECT_EQ(index.channel_id, channel);
      for (const auto& [time, at] : index.entries) {
        ASSERT_EQ(records.at(at), uint8_t(mcap::Op::message));
        ByteReader m(std::span<const uint8_t>(records).subspan(at + 9), "message");
        const auto h = mcap::parse_message_header(m);
        EXPECT_EQ(h.channel_id, channel);
        EXPECT_EQ(h.log_time, time);
        ++indexed;
      }
    }
    EXPECT_EQ(ci.message_index_length, total_length);
    uint64_t in_chunk = 0;
    for (size_t at = 0; at < records.size();) {
      uint64_t length = 0;
      for (int i = 0; i < 8; ++i) length |= uint64_t(records[at + 1 + size_t(i)]) << (8 * i);
      in_chunk += records[at] == uint8_t(mcap::Op::message);
      at += 9 + size_t(length);
    }
    EXPECT_EQ(indexed, in_chunk);
  }
}

TEST_F(McapLog, SameInputGivesTheSameBytes) {
  const std::string again = temp_path("synthetic_again.mcap");
  McapWriterOptions options;
  options.chunk_size = 48 << 10;
  test::record_synthetic_run(*run_, again, options);
  EXPECT_EQ(read_file(again), read_file(*path_));
  options.background = false;  // compressed and written inline: the same record order, the same bytes
  test::record_synthetic_run(*run_, again, options);
  EXPECT_EQ(read_file(again), read_file(*path_));
  options.compress = false;  // stored uncompressed: a different file with the same messages
  test::record_synthetic_run(*run_, again, options);
  EXPECT_NE(read_file(again), read_file(*path_));
  EXPECT_EQ(read_all(again), read_all(*path_));
}

TEST(McapWriter, ClosesChunksBySizeAndByHalfASecondOfLogTime) {
  const auto run = test::make_synthetic_run(3.5, 50, 5);
  const std::string path = temp_path("chunk_time.mcap");
  test::record_synthetic_run(run, path);  // default 4 MiB chunks: only time closes them
  const auto by_time = read_mcap_summary(path);
  ASSERT_TRUE(by_time);
  EXPECT_GE(by_time->chunk_indexes.size(), 7u);
  for (const auto& c : by_time->chunk_indexes) EXPECT_LT(c.message_end_time - c.message_start_time, 500'000'000u);

  McapWriterOptions small;
  small.chunk_size = 16 << 10;
  test::record_synthetic_run(run, path, small);
  const auto by_size = read_mcap_summary(path);
  ASSERT_TRUE(by_size);
  EXPECT_GT(by_size->chunk_indexes.size(), by_time->chunk_indexes.size());
  for (const auto& c : by_size->chunk_indexes) EXPECT_LT(c.uncompressed_size, 2 * small.chunk_size);
}

// What a process killed right after a write_message would leave is the file as it is at that moment:
// recovered, it must hold every message more than 1 s of log time older than the newest one (the
// open chunk spans under 0.5 s, and a closed chunk still in memory is waited for once it is 1 s old).
TEST(McapWriter, AKillLosesAtMostTheLastSecondOfLogTime) {
  const std::string path = temp_path("killed.mcap"), copy = temp_path("killed_copy.mcap"),
                    fixed = temp_path("killed_fixed.mcap");
  constexpr uint64_t kStep = 50'000'000, kEnd = 3'000'000'000, kMaxLoss = 1'000'000'000;
  const Bytes payload(2000, 7);
  McapWriter w(path);  // background worker, default chunks
  const uint16_t channel = w.add_channel(w.add_schema("lidarloop_msgs/msg/Blob", "ros2msg", ""), "/blob", "cdr");
  for (uint64_t t = 0; t <= kEnd; t += kStep) {
    w.write_message(channel, t, t, payload);
    write_file(copy, read_file(path));
    recover_mcap(copy, fixed);
    const uint64_t kept = read_all(fixed).size(), older = t >= kMaxLoss ? (t - kMaxLoss) / kStep + 1 : 0;
    EXPECT_GE(kept, older) << "after the message at " << t << " ns";
  }
  w.close();
}

TEST_F(McapLog, RecoverKeepsEveryCompleteChunkOfACutFile) {
  const Bytes file = read_file(*path_);
  const auto summary = read_mcap_summary(*path_);
  ASSERT_TRUE(summary);
  const std::vector<Msg> all = read_all(*path_);
  // Messages per chunk, in file order.
  std::vector<std::pair<uint64_t, size_t>> chunk_ends;  // (end offset, messages so far)
  {
    size_t so_far = 0;
    for (const auto& ci : summary->chunk_indexes) {
      ByteReader in(std::span<const uint8_t>(file).subspan(ci.chunk_start_offset + 9, ci.chunk_length - 9), "chunk");
      const Bytes records = chunk_records(mcap::parse_chunk(in), "chunk");
      for (size_t at = 0; at < records.size();) {
        uint64_t length = 0;
        for (int i = 0; i < 8; ++i) length |= uint64_t(records[at + 1 + size_t(i)]) << (8 * i);
        so_far += records[at] == uint8_t(mcap::Op::message);
        at += 9 + size_t(length);
      }
      chunk_ends.emplace_back(ci.chunk_start_offset + ci.chunk_length, so_far);
    }
  }
  // The Data End record ends where the summary starts (the footer's summary_start): a cut at or after
  // it leaves the whole data section, and recovery rightly calls that complete.
  constexpr size_t kFooterRecord = 1 + 8 + 8 + 8 + 4, kMagic = 8, kOpcodeAndLength = 1 + 8;
  uint64_t summary_start = 0;
  for (int i = 0; i < 8; ++i)
    summary_start |= uint64_t(file[file.size() - kMagic - kFooterRecord + kOpcodeAndLength + size_t(i)]) << (8 * i);
  std::mt19937_64 rng(20240607);
  const std::string cut_path = temp_path("cut.mcap"), fixed_path = temp_path("fixed.mcap");
  for (int trial = 0; trial < 20; ++trial) {
    const size_t cut = size_t(rng() % file.size());
    write_file(cut_path, std::span<const uint8_t>(file).first(cut));
    EXPECT_THROW(read_all(cut_path), InputError) << "cut at " << cut;
    EXPECT_THROW(read_mcap_summary(cut_path), InputError) << "cut at " << cut;
    McapRecoverReport report;
    ASSERT_NO_THROW(report = recover_mcap(cut_path, fixed_path)) << "cut at " << cut;
    size_t expected = 0;
    for (const auto& [end, so_far] : chunk_ends)
      if (end <= cut) expected = so_far;
    const std::vector<Msg> got = read_all(fixed_path);  // a valid file: the full check passes
    ASSERT_EQ(got.size(), expected) << "cut at " << cut << " of " << file.size();
    EXPECT_TRUE(std::equal(got.begin(), got.end(), all.begin())) << "cut at " << cut;
    EXPECT_EQ(report.messages, expected);
    EXPECT_EQ(report.complete, cut >= summary_start) << "cut at " << cut;
    EXPECT_TRUE(read_mcap_summary(fixed_path).has_value());
  }
  // An intact file recovers to the same messages.
  const McapRecoverReport whole = recover_mcap(*path_, fixed_path);
  EXPECT_TRUE(whole.complete);
  EXPECT_EQ(read_all(fixed_path), all);
  EXPECT_EQ(whole.attachments, 1u);
  EXPECT_EQ(whole.metadata, 1u);
}

TEST_F(McapLog, RecoverSkipsOnlyTheChunksACorruptionTouches) {
  Bytes file = read_file(*path_);
  const auto summary = read_mcap_summary(*path_);
  ASSERT_TRUE(summary && summary->chunk_indexes.size() > 4);
  const size_t total = read_all(*path_).size();
  const auto& victim = summary->chunk_indexes[2];
  const std::string broken = temp_path("corrupt.mcap"), fixed = temp_path("corrupt_fixed.mcap");

  // Inside the compressed data: the chunk fails its checks and is skipped, the rest is kept.
  Bytes inside = file;
  inside[victim.chunk_start_offset + victim.chunk_length / 2] ^= 0xFF;
  write_file(broken, inside);
  EXPECT_THROW(read_all(broken), InputError);
  McapRecoverReport r = recover_mcap(broken, fixed);
  EXPECT_EQ(r.skipped_chunks, 1u);
  const size_t kept_inside = read_all(fixed).size();
  EXPECT_LT(kept_inside, total);
  EXPECT_GT(kept_inside, total * 3 / 4);

  // In the chunk's length: the framing breaks; recover finds the next chunk and carries on.
  Bytes length = file;
  length[victim.chunk_start_offset + 8] = 0x7F;  // the length's top byte: far past the end of the file
  write_file(broken, length);
  EXPECT_THROW(read_all(broken), InputError);
  r = recover_mcap(broken, fixed);
  EXPECT_EQ(read_all(fixed).size(), kept_inside);
  EXPECT_GT(r.skipped_bytes, 0u);
}

TEST_F(McapLog, MutationsGiveInputErrorOrValidDataNeverACrash) {
  const Bytes file = read_file(*path_);
  const std::string mutant = temp_path("mutant.mcap"), fixed = temp_path("mutant_fixed.mcap");
  std::mt19937_64 rng(99);
  int rejected = 0;
  for (int trial = 0; trial < 150; ++trial) {
    Bytes bytes = file;
    const int kind = trial % 3;
    if (kind == 0) {  // a few flipped bits anywhere
      for (int i = 0; i < 1 + int(rng() % 4); ++i) bytes[rng() % bytes.size()] ^= uint8_t(1u << (rng() % 8));
    } else if (kind == 1) {  // an absurd value written over 8 bytes (lengths, sizes, offsets)
      const size_t at = rng() % (bytes.size() - 8);
      for (int i = 0; i < 8; ++i) bytes[at + size_t(i)] = uint8_t(rng());
    } else {  // the summary and footer region, where offsets live
      const size_t tail = std::min<size_t>(bytes.size(), 4096);
      bytes[bytes.size() - 1 - rng() % tail] ^= uint8_t(1 + rng() % 255);
    }
    write_file(mutant, bytes);
    try {
      McapReader reader(mutant);
      for (McapMessage m; reader.next(m);) decode(m);
    } catch (const InputError& e) {
      ++rejected;
      EXPECT_NE(std::string(e.what()).find(mutant), std::string::npos) << e.what();
    }
    try {
      read_mcap_summary(mutant);
    } catch (const InputError&) {
    }
    try {
      recover_mcap(mutant, fixed);
      read_all(fixed);  // whatever recover wrote is a valid file
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not an MCAP file"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(rejected, 100);  // CRCs catch nearly every change
}

TEST_F(McapLog, ExportsTumPcdAndKitti) {
  const std::string tum = temp_path("export.tum"), pcd = temp_path("export_pcd"), kitti = temp_path("export_kitti");
  std::filesystem::remove_all(pcd);
  std::filesystem::remove_all(kitti);
  const ExportResult poses = export_tum(*path_, tum);
  EXPECT_EQ(poses.topic, topics::estimate);  // the estimate when there is one
  ASSERT_EQ(poses.count, run_->estimates.size());
  // Exact: every stamp, coordinate and quaternion reads back as written to the log (logs/tum_file.hpp).
  const Bytes text = read_file(tum);
  const std::vector<TumPose> exported = parse_tum(std::string(text.begin(), text.end()), tum);
  ASSERT_EQ(exported.size(), run_->estimates.size());
  for (size_t i = 0; i < exported.size(); ++i) {
    EXPECT_EQ(exported[i].stamp_ns, run_->estimates[i].stamp_ns);
    EXPECT_EQ(exported[i].position.x(), run_->estimates[i].pose.x);
    EXPECT_EQ(exported[i].position.y(), run_->estimates[i].pose.y);
    EXPECT_EQ(ros2::yaw_of(exported[i].orientation), ros2::published_yaw(run_->estimates[i].pose.yaw));
  }
  EXPECT_EQ(export_tum(*path_, tum, std::string(topics::truth_odometry)).count, run_->truth.size());
  EXPECT_THROW(export_tum(*path_, tum, "/nothing"), InputError);

  EXPECT_EQ(export_pcd(*path_, pcd, Hdl32eCalibration{}).count, run_->scans.size());
  const Bytes first_pcd = read_file(pcd + "/000000.pcd");
  const std::string head(first_pcd.begin(), first_pcd.begin() + 300);
  EXPECT_NE(head.find("FIELDS x y z intensity ring time"), std::string::npos);
  EXPECT_NE(head.find("POINTS 500\nDATA binary\n"), std::string::npos);

  EXPECT_EQ(export_kitti(*path_, kitti, Hdl32eCalibration{}).count, run_->scans.size());
  const Bytes bin = read_file(kitti + "/velodyne_points/data/0000000000.bin");
  ASSERT_EQ(bin.size(), run_->scans[0].points.size() * 16);
  float first[4];
  std::memcpy(first, bin.data(), sizeof first);
  EXPECT_EQ(first[0], run_->scans[0].points[0].x);
  EXPECT_EQ(first[3], float(run_->scans[0].points[0].intensity) / 255.0f);
  EXPECT_TRUE(std::filesystem::exists(kitti + "/oxts/data/0000000000.txt"));
  EXPECT_EQ(kitti_timestamp(1'500'000'001), "1970-01-01 00:00:01.500000001");
}

TEST(McapReader, TinyLogCutAtEveryByte) {
  const std::string path = temp_path("tiny.mcap"), cut_path = temp_path("tiny_cut.mcap"),
                    fixed = temp_path("tiny_fixed.mcap");
  {
    McapWriter w(path);
    const uint16_t schema = w.add_schema("lidarloop_msgs/msg/Empty", "ros2msg", "");
    const uint16_t channel = w.add_channel(schema, "/a", "cdr");
    const Bytes payload = {0, 1, 0, 0, 42};
    for (uint64_t t = 0; t < 5; ++t) w.write_message(channel, t * 300'000'000, t, payload);
    w.add_metadata("m", {{"k", "v"}});
    w.close();
  }
  const Bytes file = read_file(path);
  EXPECT_EQ(read_all(path).size(), 5u);
  for (size_t cut = 0; cut < file.size(); ++cut) {
    write_file(cut_path, std::span<const uint8_t>(file).first(cut));
    EXPECT_THROW(read_all(cut_path), InputError) << cut;
    ASSERT_NO_THROW(recover_mcap(cut_path, fixed)) << cut;
    EXPECT_LE(read_all(fixed).size(), 5u);
  }
  EXPECT_THROW(McapReader(temp_path("missing.mcap")), InputError);
  write_file(cut_path, Bytes{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'});
  EXPECT_THROW(McapReader{cut_path}, InputError);
  EXPECT_THROW(recover_mcap(cut_path, fixed), InputError);
}

}  // namespace
}  // namespace lidarloop
