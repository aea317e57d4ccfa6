// An external localizer for `lidarloop run --method exec:...`: a CAN + GPS Kalman filter in one file,
// linked only with lidarloop's log library (MCAP, ROS 2 messages) and its WGS-84 frame. It shows the
// protocol of docs/external-localizer.md from the program's side:
//   - read the MCAP stream on stdin as it arrives (McapReader on a pipe blocks for the next message);
//   - take the map's origin and the car's geometry from the "lidarloop.external" metadata;
//   - after every /lidar/points message, print one JSON line with the pose at the scan's last firing
//     (or {"scan": N} before the first GPS fix), and flush;
//   - exit 0 at the end of the stream.
// It ignores the scan's points: this is the floor a LiDAR localizer has to beat, not one.
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "common/geodetic.hpp"
#include "common/pose2d.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/ros2_messages.hpp"

namespace {

using namespace lidarloop;

// The filter's noise, per second of prediction: a car on CAN odometry drifts by centimetres per metre
// (wheel radius, slip) and its yaw by a few tenths of a degree per second (steering offset).
struct FilterNoise {
  double position_m2_per_s = 0.05;
  double yaw_rad2_per_s = 1e-4;
  double min_gps_sigma_m = 0.5;  // a low-cost receiver's reported sigma is optimistic
};

struct Vehicle {
  double wheelbase_m = 2.6, steering_ratio = 16;
  Eigen::Vector2d antenna = Eigen::Vector2d::Zero();  // the GPS antenna in the vehicle frame
};

double number(const std::map<std::string, std::string>& m, const std::string& key) {
  const auto it = m.find(key);
  if (it == m.end()) throw std::runtime_error("metadata lidarloop.external has no " + key);
  return std::stod(it->second);
}

// An extended Kalman filter over (x, y, yaw) of the rear axle in the map frame.
class CanGpsFilter {
 public:
  CanGpsFilter(const Vehicle& vehicle, const FilterNoise& noise) : vehicle_(vehicle), noise_(noise) {}

  void on_can(const CanFrame& f) {
    predict_to(f.stamp_ns);
    speed_ = 0.5 * (f.wheel_speed_mps[2] + f.wheel_speed_mps[3]);  // the rear axle's centre
    steer_ = f.steering_wheel_angle_rad / vehicle_.steering_ratio;
  }

  void on_gps(const GpsFix& fix, const LocalFrame& frame) {
    if (fix.status == GpsStatus::no_fix || !std::isfinite(fix.lat_deg) || !std::isfinite(fix.lon_deg)) return;
    const Eigen::Vector2d antenna_xy = frame.to_local(fix.lat_deg, fix.lon_deg);
    const double sigma2 = std::max(
        {fix.position_covariance[0], fix.position_covariance[4], noise_.min_gps_sigma_m * noise_.min_gps_sigma_m});
    if (!initialized_) {
      // The first fix: its heading (from the receiver's course) and position, with their own doubt.
      pose_.yaw = fix.heading_rad;
      const Eigen::Vector2d lever = rotation(pose_.yaw) * vehicle_.antenna;
      pose_.x = antenna_xy.x() - lever.x();
      pose_.y = antenna_xy.y() - lever.y();
      P_ = Eigen::Vector3d(sigma2, sigma2, std::max(fix.heading_variance, 0.01)).asDiagonal();
      time_ns_ = fix.stamp_ns;
      initialized_ = true;
      return;
    }
    predict_to(fix.stamp_ns);
    // z = position + R(yaw) antenna; H is its Jacobian in (x, y, yaw).
    const Eigen::Vector2d lever = rotation(pose_.yaw) * vehicle_.antenna;
    const Eigen::Vector2d predicted(pose_.x + lever.x(), pose_.y + lever.y());
    Eigen::Matrix<double, 2, 3> H;
    H << 1, 0, -lever.y(), 0, 1, lever.x();
    const Eigen::Matrix2d S = H * P_ * H.transpose() + sigma2 * Eigen::Matrix2d::Identity();
    const Eigen::Matrix<double, 3, 2> K = P_ * H.transpose() * S.inverse();
    const Eigen::Vector3d dx = K * (antenna_xy - predicted);
    pose_ = {pose_.x + dx.x(), pose_.y + dx.y(), wrap_angle(pose_.yaw + dx.z())};
    P_ = (Eigen::Matrix3d::Identity() - K * H) * P_;
  }

  // Dead reckoning on from the last message with the last CAN frame's speed and steering (the
  // kinematic bicycle about the rear axle).
  void predict_to(int64_t t_ns) {
    if (!initialized_ || t_ns <= time_ns_) return;
    const double dt = double(t_ns - time_ns_) * 1e-9;
    const double yaw_rate = speed_ * std::tan(steer_) / vehicle_.wheelbase_m;
    const double mid_yaw = pose_.yaw + 0.5 * yaw_rate * dt;
    pose_ = {pose_.x + speed_ * dt * std::cos(mid_yaw), pose_.y + speed_ * dt * std::sin(mid_yaw),
             wrap_angle(pose_.yaw + yaw_rate * dt)};
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 2) = -speed_ * dt * std::sin(mid_yaw);
    F(1, 2) = speed_ * dt * std::cos(mid_yaw);
    P_ = F * P_ * F.transpose();
    P_.diagonal() += Eigen::Vector3d(noise_.position_m2_per_s, noise_.position_m2_per_s, noise_.yaw_rad2_per_s) * dt;
    time_ns_ = t_ns;
  }

  bool initialized() const { return initialized_; }
  const Pose2d& pose() const { return pose_; }
  const Eigen::Matrix3d& covariance() const { return P_; }

 private:
  static Eigen::Matrix2d rotation(double yaw) {
    Eigen::Matrix2d R;
    R << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
    return R;
  }

  Vehicle vehicle_;
  FilterNoise noise_;
  bool initialized_ = false;
  int64_t time_ns_ = 0;
  Pose2d pose_;
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Identity();
  double speed_ = 0, steer_ = 0;
};

void answer(int scan, const CanGpsFilter& filter, int64_t stamp_ns) {
  if (!filter.initialized()) {
    std::printf("{\"scan\": %d}\n", scan);
  } else {
    const Pose2d& p = filter.pose();
    const Eigen::Matrix3d& c = filter.covariance();
    std::printf("{\"scan\": %d, \"stamp_ns\": %lld, \"x\": %.17g, \"y\": %.17g, \"yaw\": %.17g, \"covariance\": [",
                scan, static_cast<long long>(stamp_ns), p.x, p.y, p.yaw);
    for (int i = 0; i < 9; ++i) std::printf("%s%.17g", i ? ", " : "", c(i / 3, i % 3));
    std::printf("]}\n");
  }
  std::fflush(stdout);  // the simulator waits for this line
}

}  // namespace

int main() {
  try {
    McapReader reader(stdin, "stdin");
    std::optional<LocalFrame> frame;
    std::optional<CanGpsFilter> filter;
    GpsFix fix;  // waits for its heading, which comes right after it
    bool fix_pending = false;
    int scans = 0;
    McapMessage m;
    while (reader.next(m)) {
      if (!filter) {  // the metadata comes before the first message
        std::map<std::string, std::string> meta;
        for (const auto& record : reader.metadata())
          if (record.name == "lidarloop.external") meta.insert(record.metadata.begin(), record.metadata.end());
        frame.emplace(Geodetic{number(meta, "map_origin_lat_deg"), number(meta, "map_origin_lon_deg"),
                               number(meta, "map_origin_alt_m")});
        Vehicle vehicle;
        vehicle.wheelbase_m = number(meta, "vehicle_lf_m") + number(meta, "vehicle_lr_m");
        vehicle.steering_ratio = number(meta, "vehicle_steering_ratio");
        vehicle.antenna = {number(meta, "gps_antenna_x_m"), number(meta, "gps_antenna_y_m")};
        filter.emplace(vehicle, FilterNoise{});
      }
      const std::string& topic = m.channel->topic;
      if (topic == log_topics::gps_heading && fix_pending) {
        const ros2::GnssHeading h = ros2::decode_gnss_heading(m.data, topic);
        fix.heading_rad = h.heading;
        fix.heading_variance = h.variance;
        filter->on_gps(fix, *frame);
        fix_pending = false;
      } else if (topic == log_topics::gps_fix) {
        fix = ros2::decode_nav_sat_fix(m.data, topic);
        fix_pending = true;
      } else if (topic == log_topics::vehicle_report) {
        filter->on_can(ros2::decode_vehicle_report(m.data, topic));
      } else if (topic == log_topics::scan) {
        const PointCloud cloud = ros2::decode_point_cloud(m.data, topic);
        const int64_t t = cloud.stamp_ns + scan_duration_ns(cloud);
        filter->predict_to(t);
        answer(scans++, *filter, t);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "can_gps_localizer: %s\n", e.what());
    return 1;
  }
}
