#include "logs/ros2_messages.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "logs/cdr.hpp"

namespace lidarloop::ros2 {

namespace {

enum PointFieldType : uint8_t { INT8 = 1, UINT8, INT16, UINT16, INT32, UINT32, FLOAT32, FLOAT64 };

size_t field_size(uint8_t datatype) {
  switch (datatype) {
    case INT8:
    case UINT8:
      return 1;
    case INT16:
    case UINT16:
      return 2;
    case INT32:
    case UINT32:
    case FLOAT32:
      return 4;
    case FLOAT64:
      return 8;
    default:
      return 0;
  }
}

// builtin_interfaces/Time.
void write_time(CdrWriter& w, int64_t stamp_ns) {
  const Stamp s = to_stamp(stamp_ns);
  w.i32(s.sec);
  w.u32(s.nanosec);
}

int64_t read_time(CdrReader& r) {
  Stamp s;
  s.sec = r.i32();
  s.nanosec = r.u32();
  return from_stamp(s);
}

void header(CdrWriter& w, int64_t stamp_ns, const std::string& frame_id) {
  write_time(w, stamp_ns);
  w.string(frame_id);
}

int64_t header(CdrReader& r, std::string* frame_id = nullptr) {
  const int64_t stamp = read_time(r);
  std::string frame = r.string();
  if (frame_id) *frame_id = std::move(frame);
  return stamp;
}

void vector3(CdrWriter& w, const Eigen::Vector3d& v) {
  w.f64(v.x());
  w.f64(v.y());
  w.f64(v.z());
}

Eigen::Vector3d vector3(CdrReader& r) {
  const double x = r.f64(), y = r.f64();
  return {x, y, r.f64()};
}

void quaternion(CdrWriter& w, const Eigen::Quaterniond& q) {
  w.f64(q.x());
  w.f64(q.y());
  w.f64(q.z());
  w.f64(q.w());
}

Eigen::Quaterniond quaternion(CdrReader& r) {
  const double x = r.f64(), y = r.f64(), z = r.f64(), w = r.f64();
  return Eigen::Quaterniond(w, x, y, z);
}

void store32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}

uint64_t load(const uint8_t* p, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}

double field_value(const uint8_t* p, uint8_t datatype) {
  switch (datatype) {
    case INT8:
      return double(int8_t(p[0]));
    case UINT8:
      return double(p[0]);
    case INT16:
      return double(int16_t(load(p, 2)));
    case UINT16:
      return double(load(p, 2));
    case INT32:
      return double(int32_t(load(p, 4)));
    case UINT32:
      return double(load(p, 4));
    case FLOAT32:
      return double(std::bit_cast<float>(uint32_t(load(p, 4))));
    default:
      return std::bit_cast<double>(load(p, 8));
  }
}

// Conversions that stay defined for any input (NaN, huge values) from a foreign cloud.
double clamp_to(double v, double hi) { return v > 0 ? std::min(v, hi) : 0.0; }  // NaN -> 0
float to_float(double v) {
  if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
  const double big = std::numeric_limits<float>::max();
  return v > big    ? std::numeric_limits<float>::infinity()
         : v < -big ? -std::numeric_limits<float>::infinity()
                    : float(v);
}

struct Field {
  uint32_t offset = 0;
  uint8_t datatype = 0;
  bool present = false;
};

}  // namespace

Stamp to_stamp(int64_t ns) {
  int64_t sec = ns / kNsPerS, rem = ns % kNsPerS;
  if (rem < 0) {
    rem += kNsPerS;
    --sec;
  }
  return {int32_t(sec), uint32_t(rem)};
}

int64_t from_stamp(Stamp s) { return int64_t(s.sec) * kNsPerS + int64_t(s.nanosec); }

Bytes encode_point_cloud(const PointCloud& cloud, const std::string& frame_id) {
  Bytes out;
  encode_point_cloud(cloud, frame_id, out);
  return out;
}

void encode_point_cloud(const PointCloud& cloud, const std::string& frame_id, Bytes& out) {
  static constexpr struct {
    const char* name;
    uint32_t offset;
    uint8_t datatype;
  } fields[] = {{"x", 0, FLOAT32},          {"y", 4, FLOAT32},    {"z", 8, FLOAT32},
                {"intensity", 12, FLOAT32}, {"ring", 16, UINT16}, {"t_ns", 20, UINT32}};
  const size_t n = cloud.points.size();
  CdrWriter w(std::move(out));
  w.reserve(256 + n * kPointStep);
  header(w, cloud.stamp_ns, frame_id);
  w.u32(1);
  w.u32(uint32_t(n));
  w.sequence_length(std::size(fields));
  for (const auto& f : fields) {
    w.string(f.name);
    w.u32(f.offset);
    w.u8(f.datatype);
    w.u32(1);
  }
  w.boolean(false);
  w.u32(kPointStep);
  w.u32(uint32_t(n * kPointStep));
  w.sequence_length(n * kPointStep);
  auto& buf = w.buffer();
  const size_t start = buf.size();
  buf.resize(start + n * kPointStep);  // zero-filled: the padding bytes are 0
  uint8_t* p = buf.data() + start;
  for (const LidarPoint& pt : cloud.points) {
    store32(p + 0, std::bit_cast<uint32_t>(pt.x));
    store32(p + 4, std::bit_cast<uint32_t>(pt.y));
    store32(p + 8, std::bit_cast<uint32_t>(pt.z));
    store32(p + 12, std::bit_cast<uint32_t>(float(pt.intensity)));
    p[16] = uint8_t(pt.ring);
    p[17] = uint8_t(pt.ring >> 8);
    store32(p + 20, pt.t_ns);
    p += kPointStep;
  }
  w.boolean(true);
  out = std::move(w.buffer());
}

PointCloud decode_point_cloud(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  PointCloud cloud;
  cloud.stamp_ns = header(r);
  const uint32_t height = r.u32(), width = r.u32();
  Field x, y, z, intensity, ring, t_ns, time;
  const uint32_t field_count = r.sequence_length(4 + 4 + 1 + 4);
  for (uint32_t i = 0; i < field_count; ++i) {
    const std::string name = r.string();
    Field f;
    f.offset = r.u32();
    f.datatype = r.u8();
    r.u32();  // count
    f.present = true;
    if (field_size(f.datatype) == 0) r.fail("PointCloud2 field '" + name + "' has unknown datatype");
    if (name == "x")
      x = f;
    else if (name == "y")
      y = f;
    else if (name == "z")
      z = f;
    else if (name == "intensity")
      intensity = f;
    else if (name == "ring")
      ring = f;
    else if (name == "t_ns" || name == "t" || name == "time_stamp")
      t_ns = f;
    else if (name == "time")
      time = f;
  }
  const bool big_endian = r.boolean();
  const uint32_t point_step = r.u32(), row_step = r.u32();
  const uint32_t size = r.sequence_length(1);
  const View data = r.raw(size);
  if (big_endian) r.fail("big-endian PointCloud2 is not supported");
  for (const Field* f : {&x, &y, &z}) {
    if (!f->present || (f->datatype != FLOAT32 && f->datatype != FLOAT64))
      r.fail("PointCloud2 needs FLOAT32 or FLOAT64 fields x, y and z");
  }
  for (const Field* f : {&x, &y, &z, &intensity, &ring, &t_ns, &time}) {
    if (f->present && uint64_t(f->offset) + field_size(f->datatype) > point_step)
      r.fail("PointCloud2 field at offset " + std::to_string(f->offset) + " lies outside point_step " +
             std::to_string(point_step));
  }
  const uint64_t points = uint64_t(height) * width;
  if (points > 0 && ((height > 1 && uint64_t(width) * point_step > row_step) ||
                     uint64_t(height - 1) * row_step + uint64_t(width) * point_step > data.size()))
    r.fail("PointCloud2 data (" + std::to_string(data.size()) + " bytes) is smaller than " + std::to_string(height) +
           " x " + std::to_string(width) + " points of " + std::to_string(point_step) + " bytes");
  cloud.points.resize(size_t(points));
  size_t k = 0;
  for (uint32_t row = 0; row < height; ++row) {
    for (uint32_t col = 0; col < width; ++col) {
      const uint8_t* p = data.data() + size_t(row) * row_step + size_t(col) * point_step;
      LidarPoint& pt = cloud.points[k++];
      pt.x = to_float(field_value(p + x.offset, x.datatype));
      pt.y = to_float(field_value(p + y.offset, y.datatype));
      pt.z = to_float(field_value(p + z.offset, z.datatype));
      if (intensity.present)
        pt.intensity = uint8_t(std::round(clamp_to(field_value(p + intensity.offset, intensity.datatype), 255)));
      if (ring.present) pt.ring = uint16_t(clamp_to(field_value(p + ring.offset, ring.datatype), 65535));
      if (t_ns.present)
        pt.t_ns = uint32_t(clamp_to(field_value(p + t_ns.offset, t_ns.datatype), 4294967295.0));
      else if (time.present)
        pt.t_ns = uint32_t(std::round(clamp_to(field_value(p + time.offset, time.datatype) * 1e9, 4294967295.0)));
    }
  }
  return cloud;
}

Bytes encode_nav_sat_fix(const GpsFix& fix, const std::string& frame_id) {
  CdrWriter w;
  header(w, fix.stamp_ns, frame_id);
  w.i8(int8_t(fix.status));
  w.u16(1);  // SERVICE_GPS
  w.f64(fix.lat_deg);
  w.f64(fix.lon_deg);
  w.f64(fix.alt_m);
  for (double c : fix.position_covariance) w.f64(c);
  w.u8(fix.status == GpsStatus::no_fix ? 0 : 3);  // COVARIANCE_TYPE_UNKNOWN : COVARIANCE_TYPE_KNOWN
  return std::move(w.buffer());
}

GpsFix decode_nav_sat_fix(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  GpsFix fix;
  fix.stamp_ns = header(r);
  fix.status = GpsStatus(r.i8());
  r.u16();
  fix.lat_deg = r.f64();
  fix.lon_deg = r.f64();
  fix.alt_m = r.f64();
  for (double& c : fix.position_covariance) c = r.f64();
  r.u8();
  return fix;
}

Bytes encode_gnss_heading(const GpsFix& fix, const std::string& frame_id) {
  CdrWriter w;
  header(w, fix.stamp_ns, frame_id);
  w.f64(fix.heading_rad);
  w.f64(fix.heading_variance);
  return std::move(w.buffer());
}

GnssHeading decode_gnss_heading(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  GnssHeading h;
  h.stamp_ns = header(r);
  h.heading = r.f64();
  h.variance = r.f64();
  return h;
}

Bytes encode_vehicle_report(const CanFrame& frame, const std::string& frame_id) {
  CdrWriter w;
  header(w, frame.stamp_ns, frame_id);
  for (double v : frame.wheel_speed_mps) w.f64(v);
  w.f64(frame.steering_wheel_angle_rad);
  return std::move(w.buffer());
}

CanFrame decode_vehicle_report(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  CanFrame f;
  f.stamp_ns = header(r);
  for (double& v : f.wheel_speed_mps) v = r.f64();
  f.steering_wheel_angle_rad = r.f64();
  return f;
}

Bytes encode_truth_state(const TruthSample& t) {
  CdrWriter w;
  header(w, t.stamp_ns, "map");
  for (double v : {t.pose.x, t.pose.y, t.pose.yaw, t.speed, t.yaw_rate, t.steer, t.cross_track}) w.f64(v);
  return std::move(w.buffer());
}

TruthSample decode_truth_state(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  TruthSample t;
  t.stamp_ns = header(r);
  for (double* v : {&t.pose.x, &t.pose.y, &t.pose.yaw, &t.speed, &t.yaw_rate, &t.steer, &t.cross_track}) *v = r.f64();
  return t;
}

Bytes encode_curb_visibility(const CurbVisibility& v) {
  CdrWriter w;
  header(w, v.stamp_ns, "map");
  for (int n : {v.visible, v.hidden, v.blocked_by_world}) w.i32(n);
  return std::move(w.buffer());
}

CurbVisibility decode_curb_visibility(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  CurbVisibility v;
  v.stamp_ns = header(r);
  for (int* n : {&v.visible, &v.hidden, &v.blocked_by_world}) *n = r.i32();
  return v;
}

Odometry planar_odometry(int64_t stamp_ns, const Pose2d& pose, const Eigen::Matrix3d& cov_xy_yaw,
                         const std::string& frame_id, const std::string& child_frame_id) {
  Odometry o;
  o.stamp_ns = stamp_ns;
  o.frame_id = frame_id;
  o.child_frame_id = child_frame_id;
  o.position = {pose.x, pose.y, 0};
  o.orientation = yaw_quaternion(pose.yaw);
  constexpr int kIndex[3] = {0, 1, 5};  // x, y, rotation about z in the 6x6 covariance
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) o.pose_covariance[size_t(kIndex[i] * 6 + kIndex[j])] = cov_xy_yaw(i, j);
  return o;
}

namespace {

// geometry_msgs/PoseWithCovariance, inside Odometry and PoseWithCovarianceStamped alike.
void pose_with_covariance(CdrWriter& w, const Odometry& o) {
  vector3(w, o.position);
  quaternion(w, o.orientation);
  for (double c : o.pose_covariance) w.f64(c);
}

void pose_with_covariance(CdrReader& r, Odometry& o) {
  o.position = vector3(r);
  o.orientation = quaternion(r);
  for (double& c : o.pose_covariance) c = r.f64();
}

}  // namespace

Bytes encode_odometry(const Odometry& o) {
  CdrWriter w;
  header(w, o.stamp_ns, o.frame_id);
  w.string(o.child_frame_id);
  pose_with_covariance(w, o);
  vector3(w, o.linear);
  vector3(w, o.angular);
  for (double c : o.twist_covariance) w.f64(c);
  return std::move(w.buffer());
}

Odometry decode_odometry(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  Odometry o;
  o.stamp_ns = header(r, &o.frame_id);
  o.child_frame_id = r.string();
  pose_with_covariance(r, o);
  o.linear = vector3(r);
  o.angular = vector3(r);
  for (double& c : o.twist_covariance) c = r.f64();
  return o;
}

Eigen::Matrix3d planar_covariance(const std::array<double, 36>& c) {
  constexpr size_t kIndex[3] = {0, 1, 5};  // as in planar_odometry
  Eigen::Matrix3d cov;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) cov(i, j) = c[kIndex[i] * 6 + kIndex[j]];
  return cov;
}

Bytes encode_pose_with_covariance_stamped(const Odometry& o) {
  CdrWriter w;
  header(w, o.stamp_ns, o.frame_id);
  pose_with_covariance(w, o);
  return std::move(w.buffer());
}

Odometry decode_pose_with_covariance_stamped(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  Odometry o;
  o.stamp_ns = header(r, &o.frame_id);
  pose_with_covariance(r, o);
  return o;
}

Eigen::Quaterniond yaw_quaternion(double yaw) { return Eigen::Quaterniond(std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)); }

double yaw_of(const Eigen::Quaterniond& q) {
  // w^2 + x^2 - y^2 - z^2 is 1 - 2 (y^2 + z^2) for a unit quaternion, and scales with the quaternion
  // as the first argument does.
  return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), q.w() * q.w() + q.x() * q.x() - q.y() * q.y() - q.z() * q.z());
}

Transform make_transform(int64_t stamp_ns, const std::string& parent, const std::string& child,
                         const Eigen::Isometry3d& pose) {
  return {stamp_ns, parent, child, pose.translation(), Eigen::Quaterniond(pose.rotation())};
}

Transform planar_transform(int64_t stamp_ns, const std::string& parent, const std::string& child, const Pose2d& pose) {
  return {stamp_ns, parent, child, {pose.x, pose.y, 0}, yaw_quaternion(pose.yaw)};
}

Bytes encode_tf(const std::vector<Transform>& transforms) {
  CdrWriter w;
  w.sequence_length(transforms.size());
  for (const auto& t : transforms) {
    header(w, t.stamp_ns, t.parent);
    w.string(t.child);
    vector3(w, t.translation);
    quaternion(w, t.rotation);
  }
  return std::move(w.buffer());
}

std::vector<Transform> decode_tf(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  const uint32_t n = r.sequence_length(4 + 4 + 4 + 4 + 7 * 8);
  std::vector<Transform> out(n);
  for (auto& t : out) {
    t.stamp_ns = header(r, &t.parent);
    t.child = r.string();
    t.translation = vector3(r);
    t.rotation = quaternion(r);
  }
  return out;
}

Bytes encode_pose_stamped(int64_t stamp_ns, const std::string& frame_id, const Eigen::Isometry3d& pose) {
  CdrWriter w;
  header(w, stamp_ns, frame_id);
  vector3(w, pose.translation());
  quaternion(w, Eigen::Quaterniond(pose.rotation()));
  return std::move(w.buffer());
}

Transform decode_pose_stamped(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  Transform t;
  t.stamp_ns = header(r, &t.parent);
  t.translation = vector3(r);
  t.rotation = quaternion(r);
  return t;
}

Bytes encode_actor_array(int64_t stamp_ns, const std::vector<ActorState>& actors, const std::string& frame_id) {
  CdrWriter w;
  header(w, stamp_ns, frame_id);
  w.sequence_length(actors.size());
  for (const auto& a : actors) {
    w.string(a.name);
    w.string(a.type);
    w.f64(a.pose.x);
    w.f64(a.pose.y);
    w.f64(a.pose.yaw);
  }
  return std::move(w.buffer());
}

std::vector<ActorState> decode_actor_array(View cdr, const std::string& context, int64_t* stamp_ns) {
  CdrReader r(cdr, context);
  const int64_t stamp = header(r);
  if (stamp_ns) *stamp_ns = stamp;
  const uint32_t n = r.sequence_length(4 + 4 + 3 * 8);
  std::vector<ActorState> out(n);
  for (auto& a : out) {
    a.name = r.string();
    a.type = r.string();
    a.pose.x = r.f64();
    a.pose.y = r.f64();
    a.pose.yaw = r.f64();
  }
  return out;
}

Bytes encode_diagnostic_array(const DiagnosticArray& array) {
  CdrWriter w;
  header(w, array.stamp_ns, array.frame_id);
  w.sequence_length(array.status.size());
  for (const DiagnosticStatus& s : array.status) {
    w.u8(s.level);
    w.string(s.name);
    w.string(s.message);
    w.string(s.hardware_id);
    w.sequence_length(s.values.size());
    for (const auto& [key, value] : s.values) {
      w.string(key);
      w.string(value);
    }
  }
  return std::move(w.buffer());
}

DiagnosticArray decode_diagnostic_array(View cdr, const std::string& context) {
  // The least a status and a key-value pair take: their strings' lengths and the sequence counts.
  constexpr size_t kMinStatusBytes = 1 + 4 * 4, kMinKeyValueBytes = 2 * 4;
  CdrReader r(cdr, context);
  DiagnosticArray a;
  a.stamp_ns = header(r, &a.frame_id);
  a.status.resize(r.sequence_length(kMinStatusBytes));
  for (DiagnosticStatus& s : a.status) {
    s.level = r.u8();
    s.name = r.string();
    s.message = r.string();
    s.hardware_id = r.string();
    s.values.resize(r.sequence_length(kMinKeyValueBytes));
    for (auto& [key, value] : s.values) {
      key = r.string();
      value = r.string();
    }
  }
  return a;
}

Bytes encode_velodyne_scan(const VelodyneScan& scan) {
  CdrWriter w;
  w.reserve(scan.packets.size() * (8 + kVelodynePacketSize + 2));
  header(w, scan.stamp_ns, scan.frame_id);
  w.sequence_length(scan.packets.size());
  for (const auto& p : scan.packets) {
    write_time(w, p.stamp_ns);
    w.raw(p.data);
  }
  return std::move(w.buffer());
}

VelodyneScan decode_velodyne_scan(View cdr, const std::string& context) {
  CdrReader r(cdr, context);
  VelodyneScan scan;
  scan.stamp_ns = header(r, &scan.frame_id);
  scan.packets.resize(r.sequence_length(8 + kVelodynePacketSize));
  for (auto& p : scan.packets) {
    p.stamp_ns = read_time(r);
    const View data = r.raw(kVelodynePacketSize);
    std::copy(data.begin(), data.end(), p.data.begin());
  }
  return scan;
}

}  // namespace lidarloop::ros2
