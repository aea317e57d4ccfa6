// An external localizer for `lidarloop run --method exec:...`: a CAN + GPS Kalman filter in one file,
// linked only with lidarloop's log library (MCAP, ROS 2 messages) and its WGS-84 frame. It shows the
// protocol of docs/external-localizer.md from the program's side:
//   - read the MCAP stream on stdin as it arrives (McapReader on a pipe blocks for the next message);
//   - take the map's origin and the car's geometry from the "lidarloop.external" metadata;
//   - after every /lidar/points message, print one JSON line with the pose at the scan's last firing
//     (or {"scan": N} before the first GPS fix), and flush;
//   - say how far it can be trusted: protection bounds from its covariance (Integrity), and `lost`
//     when the GPS keeps disagreeing with it, until it has started over from the GPS and the fixes
//     agree again;
//   - exit 0 at the end of the stream.
// It ignores the scan's points: this is the floor a LiDAR localizer has to beat, not one.
#include <algorithm>
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

// The filter's noise model. The covariance it reports is honest only if these are: the GPS figures
// are the low-cost receiver's (sim/gps_model.hpp: the paper's receiver, ~2 m per axis); for a receiver
// of your own, measure them on a static antenna (the scatter and the time its error takes to wander).
struct FilterNoise {
  // The fix-to-fix scatter; the rest of the variance the receiver reports is its slowly wandering bias.
  double gps_white_sigma_m = 0.4;
  // How long the bias takes to wander (correlation time): minutes, so over a 20 s drive it is nearly
  // constant. A filter that took the fixes' errors as independent would average the bias away on paper
  // (a 2 m error reported as 0.2 m: NEES 45), not in fact: it is a state here, as on a real car.
  double gps_bias_tau_s = 120.0;
  // CAN odometry's error, per second of driving: the distance by its scale (tyre radius 0.5 %,
  // sim/can_model.hpp, doubled for slip), sideways by the rear axle's slip angle, which the kinematic
  // bicycle leaves out (a few tenths of a degree to a degree at city speeds), and the yaw rate by the
  // same model's error while the car weaves (half a degree per second). The first two are estimates
  // from those sources; the yaw rate's was calibrated on external_closed_loop's seeds 1-8 (0.005 rad/s
  // gave a heading NEES of 2.2 on seed 23, 0.02 one of 0.4 open loop over seeds 1-8).
  double odometry_scale_sigma = 0.01;
  double side_slip_sigma_rad = 0.01;
  double yaw_rate_sigma_rad_per_s = 0.01;
};

// The integrity it claims, stated once: the probability that its error stays within a protection
// bound, per axis and scan, and that an honest fix passes the GPS's innovation gate. lidarloop's
// built-in localizer uses the same (localizer/protection_bound.hpp): one frame in ten thousand.
struct Integrity {
  double probability = 0.9999;
  // A fix refused by the gate is left out; this many refused in a row (0.3 s of fixes at 10 Hz) mean
  // the GPS and the dead reckoning disagree for good: a jump, which a CAN + GPS filter cannot tell
  // from the car having moved. It then says it is lost and starts over from the next fix. An honest
  // filter refuses three honest fixes in a row once in 10^12.
  int lost_after_refused_fixes = 3;
  // Lost until this many fixes in a row have passed the gate after the new start: the fixes agree
  // with each other again, so the new level is not a glitch of one fix.
  int found_after_accepted_fixes = 3;
};

// k with P(|N(0, 1)| <= k) = probability (3.89 for 0.9999): the bound on one axis is k sigma.
double normal_two_sided_quantile(double probability) {
  // P(|N| > k) = erfc(k / sqrt 2) decreases in k: bisection, far below any use's precision.
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > 1 - probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The squared Mahalanobis distance of a 2-D innovation is chi-square with 2 degrees of freedom, whose
// quantile has a closed form: P(d^2 <= g) = 1 - exp(-g / 2).
double chi_square_2_quantile(double probability) { return -2.0 * std::log(1.0 - probability); }

struct Vehicle {
  double wheelbase_m = 2.6, steering_ratio = 16;
  Eigen::Vector2d antenna = Eigen::Vector2d::Zero();  // the GPS antenna in the vehicle frame
};

double number(const std::map<std::string, std::string>& m, const std::string& key) {
  const auto it = m.find(key);
  if (it == m.end()) throw std::runtime_error("metadata lidarloop.external has no " + key);
  return std::stod(it->second);
}

// An extended Kalman filter over the rear axle's (x, y, yaw) in the map frame and the receiver's
// position bias (bx, by): a fix is position + R(yaw) antenna + bias + white noise.
class CanGpsFilter {
 public:
  using State = Eigen::Matrix<double, 5, 1>;
  using Covariance = Eigen::Matrix<double, 5, 5>;
  enum { kX, kY, kYaw, kBx, kBy };

  CanGpsFilter(const Vehicle& vehicle, const FilterNoise& noise, const Integrity& integrity)
      : vehicle_(vehicle), noise_(noise), integrity_(integrity), gate_(chi_square_2_quantile(integrity.probability)) {}

  void on_can(const CanFrame& f) {
    predict_to(f.stamp_ns);
    speed_ = 0.5 * (f.wheel_speed_mps[2] + f.wheel_speed_mps[3]);  // the rear axle's centre
    steer_ = f.steering_wheel_angle_rad / vehicle_.steering_ratio;
  }

  void on_gps(const GpsFix& fix, const LocalFrame& frame) {
    if (fix.status == GpsStatus::no_fix || !std::isfinite(fix.lat_deg) || !std::isfinite(fix.lon_deg)) return;
    const Eigen::Vector2d antenna_xy = frame.to_local(fix.lat_deg, fix.lon_deg);
    const double reported = std::max(fix.position_covariance[0], fix.position_covariance[4]);
    const double white = noise_.gps_white_sigma_m * noise_.gps_white_sigma_m;
    if (!initialized_ || start_over_) {
      start_from(fix, antenna_xy, reported, white);
      return;
    }
    predict_to(fix.stamp_ns);
    // z = position + R(yaw) antenna + bias; H is its Jacobian.
    const Eigen::Vector2d lever = rotation(x_(kYaw)) * vehicle_.antenna;
    const Eigen::Vector2d predicted = x_.head<2>() + lever + x_.tail<2>();
    Eigen::Matrix<double, 2, 5> H;
    H << 1, 0, -lever.y(), 1, 0, 0, 1, lever.x(), 0, 1;
    const Eigen::Matrix2d R = white * Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d S = H * P_ * H.transpose() + R;
    const Eigen::Vector2d innovation = antenna_xy - predicted;
    if (innovation.dot(S.inverse() * innovation) > gate_) {  // this fix disagrees: leave it out
      accepted_in_row_ = 0;
      if (++refused_in_row_ >= integrity_.lost_after_refused_fixes) {
        lost_ = true;
        start_over_ = true;  // from the next fix: this one's disagreement is all we know
      }
      return;
    }
    refused_in_row_ = 0;
    if (lost_ && ++accepted_in_row_ >= integrity_.found_after_accepted_fixes) lost_ = false;
    const Eigen::Matrix<double, 5, 2> K = P_ * H.transpose() * S.inverse();
    x_ += K * innovation;
    x_(kYaw) = wrap_angle(x_(kYaw));
    // Joseph form: stays symmetric and positive over thousands of updates.
    const Covariance IKH = Covariance::Identity() - K * H;
    P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  }

  // Dead reckoning on from the last message with the last CAN frame's speed and steering (the
  // kinematic bicycle about the rear axle); the bias decays towards 0 as a first-order Gauss-Markov
  // process, its variance kept stationary.
  void predict_to(int64_t t_ns) {
    if (!initialized_ || t_ns <= time_ns_) return;
    const double dt = double(t_ns - time_ns_) * 1e-9;
    const double yaw_rate = speed_ * std::tan(steer_) / vehicle_.wheelbase_m;
    const double mid_yaw = x_(kYaw) + 0.5 * yaw_rate * dt;
    const double c = std::cos(mid_yaw), s = std::sin(mid_yaw);
    const double phi = std::exp(-dt / noise_.gps_bias_tau_s);
    x_(kX) += speed_ * dt * c;
    x_(kY) += speed_ * dt * s;
    x_(kYaw) = wrap_angle(x_(kYaw) + yaw_rate * dt);
    x_.tail<2>() *= phi;
    Covariance F = Covariance::Identity();
    F(kX, kYaw) = -speed_ * dt * s;
    F(kY, kYaw) = speed_ * dt * c;
    F(kBx, kBx) = F(kBy, kBy) = phi;
    P_ = F * P_ * F.transpose();
    // Odometry's error along and across the car, turned into the map frame.
    const double along = std::pow(noise_.odometry_scale_sigma * speed_, 2) * dt;
    const double across = std::pow(noise_.side_slip_sigma_rad * speed_, 2) * dt;
    P_(kX, kX) += along * c * c + across * s * s;
    P_(kY, kY) += along * s * s + across * c * c;
    P_(kX, kY) += (along - across) * c * s;
    P_(kY, kX) += (along - across) * c * s;
    P_(kYaw, kYaw) += noise_.yaw_rate_sigma_rad_per_s * noise_.yaw_rate_sigma_rad_per_s * dt;
    P_(kBx, kBx) += bias_variance_ * (1 - phi * phi);
    P_(kBy, kBy) += bias_variance_ * (1 - phi * phi);
    time_ns_ = t_ns;
  }

  bool initialized() const { return initialized_; }
  bool lost() const { return lost_; }
  Pose2d pose() const { return {x_(kX), x_(kY), x_(kYaw)}; }
  Eigen::Matrix3d covariance() const { return P_.topLeftCorner<3, 3>(); }  // (x, y, yaw)

 private:
  // The filter from one fix alone: at the start, and after the GPS and the dead reckoning parted.
  void start_from(const GpsFix& fix, const Eigen::Vector2d& antenna_xy, double reported, double white) {
    // The receiver's reported variance is its whole error, bias and scatter. The fix's bias is
    // unknown, so the pose inherits it (pose = fix - lever - bias: they are anti-correlated).
    bias_variance_ = std::max(reported - white, 0.0);
    const Eigen::Vector2d lever = rotation(fix.heading_rad) * vehicle_.antenna;
    x_ << antenna_xy - lever, fix.heading_rad, 0, 0;
    P_.setZero();
    P_(kX, kX) = P_(kY, kY) = reported;
    P_(kBx, kBx) = P_(kBy, kBy) = bias_variance_;
    P_(kX, kBx) = P_(kBx, kX) = P_(kY, kBy) = P_(kBy, kY) = -bias_variance_;
    P_(kYaw, kYaw) = fix.heading_variance;
    time_ns_ = fix.stamp_ns;
    initialized_ = true;
    start_over_ = false;
    refused_in_row_ = accepted_in_row_ = 0;
  }

  static Eigen::Matrix2d rotation(double yaw) {
    Eigen::Matrix2d R;
    R << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
    return R;
  }

  Vehicle vehicle_;
  FilterNoise noise_;
  Integrity integrity_;
  double gate_;  // on the innovation's squared Mahalanobis distance
  bool initialized_ = false;
  bool lost_ = false, start_over_ = false;
  int refused_in_row_ = 0, accepted_in_row_ = 0;  // consecutive fixes the gate refused, accepted
  int64_t time_ns_ = 0;
  State x_ = State::Zero();
  Covariance P_ = Covariance::Identity();
  double bias_variance_ = 0;
  double speed_ = 0, steer_ = 0;
};

// The protection bounds: k sigma of the position's covariance across and along the car (its own
// vehicle frame, as the protocol wants them), k for the stated probability per axis.
Eigen::Vector2d protection_bounds(const Pose2d& pose, const Eigen::Matrix3d& covariance, double k) {
  const Eigen::Vector2d forward(std::cos(pose.yaw), std::sin(pose.yaw)), left(-forward.y(), forward.x());
  const Eigen::Matrix2d P = covariance.topLeftCorner<2, 2>();
  auto bound = [&](const Eigen::Vector2d& u) { return k * std::sqrt(std::max(0.0, u.dot(P * u))); };
  return {bound(left), bound(forward)};
}

void answer(int scan, const CanGpsFilter& filter, int64_t stamp_ns, double k) {
  if (!filter.initialized()) {
    std::printf("{\"scan\": %d}\n", scan);
  } else {
    const Pose2d p = filter.pose();
    const Eigen::Matrix3d c = filter.covariance();
    std::printf("{\"scan\": %d, \"stamp_ns\": %lld, \"x\": %.17g, \"y\": %.17g, \"yaw\": %.17g, \"covariance\": [",
                scan, static_cast<long long>(stamp_ns), p.x, p.y, p.yaw);
    for (int i = 0; i < 9; ++i) std::printf("%s%.17g", i ? ", " : "", c(i / 3, i % 3));
    const Eigen::Vector2d bounds = protection_bounds(p, c, k);
    std::printf("], \"lost\": %s, \"protection\": [%.17g, %.17g]}\n", filter.lost() ? "true" : "false", bounds.x(),
                bounds.y());
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
    const Integrity integrity;
    const double k = normal_two_sided_quantile(integrity.probability);
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
        filter.emplace(vehicle, FilterNoise{}, integrity);
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
        answer(scans++, *filter, t, k);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "can_gps_localizer: %s\n", e.what());
    return 1;
  }
}
