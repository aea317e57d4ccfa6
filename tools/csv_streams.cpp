#include "tools/csv_streams.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "tools/ply_file.hpp"

namespace lidarloop {

CsvStreams::CsvStreams(const std::string& dir, const LocalFrame& frame, int scan_every)
    : dir_(dir), frame_(frame), scan_every_(scan_every) {
  std::error_code ec;
  std::filesystem::create_directories(dir + "/scans", ec);
  if (ec) throw InputError(dir + ": cannot create output folder (" + ec.message() + ")");
  truth_ = open("truth.csv",
                "stamp_ns,x_m,y_m,yaw_rad,speed_mps,yaw_rate_radps,steer_rad,cross_track_m,body_heave_m,"
                "body_pitch_rad,body_roll_rad");
  can_ = open("can.csv", "stamp_ns,wheel_fl_mps,wheel_fr_mps,wheel_rl_mps,wheel_rr_mps,steering_wheel_rad");
  gps_ = open("gps.csv",
              "stamp_ns,status,lat_deg,lon_deg,alt_m,heading_rad,var_east_m2,var_north_m2,var_heading_rad2,x_m,y_m");
  rtk_ = open("rtk.csv",
              "stamp_ns,status,lat_deg,lon_deg,alt_m,heading_rad,var_east_m2,var_north_m2,var_heading_rad2,x_m,y_m");
  actors_ = open("actors.csv", "stamp_ns,name,type,x_m,y_m,yaw_rad");
}

std::ofstream CsvStreams::open(const std::string& name, const std::string& header) {
  std::ofstream out(dir_ + "/" + name);
  if (!out) throw InputError(dir_ + "/" + name + ": cannot write file (" + std::strerror(errno) + ")");
  out.precision(10);
  out << header << '\n';
  return out;
}

void CsvStreams::check(const std::ofstream& out, const char* name) const {
  if (!out) throw InputError(dir_ + "/" + name + ": write failed (" + std::strerror(errno) + ")");
}

void CsvStreams::finish() {
  const std::pair<std::ofstream*, const char*> files[] = {
      {&truth_, "truth.csv"}, {&can_, "can.csv"}, {&gps_, "gps.csv"}, {&rtk_, "rtk.csv"}, {&actors_, "actors.csv"}};
  for (const auto& [out, name] : files) {
    out->close();
    check(*out, name);
  }
}

void CsvStreams::on_truth(const TruthSample& s) {
  truth_ << s.stamp_ns << ',' << s.pose.x << ',' << s.pose.y << ',' << s.pose.yaw << ',' << s.speed << ',' << s.yaw_rate
         << ',' << s.steer << ',' << s.cross_track << ',' << s.body.heave << ',' << s.body.pitch << ',' << s.body.roll
         << '\n';
  check(truth_, "truth.csv");
  if (ego_path_.empty() || (ego_path_.back() - Eigen::Vector2d(s.pose.x, s.pose.y)).norm() > 0.5)
    ego_path_.emplace_back(s.pose.x, s.pose.y);
  cross_track_sq_ += s.cross_track * s.cross_track;
  ++truth_count_;
}

void CsvStreams::on_can(const CanFrame& f) {
  can_ << f.stamp_ns;
  for (double w : f.wheel_speed_mps) can_ << ',' << w;
  can_ << ',' << f.steering_wheel_angle_rad << '\n';
  check(can_, "can.csv");
}

void CsvStreams::write_fix(std::ofstream& out, const GpsFix& f) {
  out << f.stamp_ns << ',' << int(f.status);
  if (f.status == GpsStatus::no_fix) {
    out << ",,,,,,,,,\n";
    return;
  }
  const Eigen::Vector2d xy = frame_.to_local(f.lat_deg, f.lon_deg);
  out.precision(12);
  out << ',' << f.lat_deg << ',' << f.lon_deg;
  out.precision(10);
  out << ',' << f.alt_m << ',' << f.heading_rad << ',' << f.position_covariance[0] << ',' << f.position_covariance[4]
      << ',' << f.heading_variance << ',' << xy.x() << ',' << xy.y() << '\n';
}

void CsvStreams::on_gps(const GpsFix& f) {
  write_fix(gps_, f);
  check(gps_, "gps.csv");
}
void CsvStreams::on_rtk(const GpsFix& f) {
  write_fix(rtk_, f);
  check(rtk_, "rtk.csv");
}

void CsvStreams::on_scan(const PointCloud& cloud, const Eigen::Isometry3d&) {
  if (scan_every_ > 0 && scans_ % size_t(scan_every_) == 0) {
    char name[64];
    std::snprintf(name, sizeof name, "/scans/scan_%06zu.ply", scans_);
    write_ply(dir_ + name, cloud);
  }
  ++scans_;
}

void CsvStreams::on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) {
  for (const auto& a : actors) {
    actors_ << stamp_ns << ',' << a.name << ',' << actor_type_name(a.type) << ',' << a.pose.x << ',' << a.pose.y << ','
            << a.pose.yaw << '\n';
    check(actors_, "actors.csv");
    Polyline2d& path = actor_paths_[a.name];
    if (path.empty() || (path.back() - Eigen::Vector2d(a.pose.x, a.pose.y)).norm() > 0.5)
      path.emplace_back(a.pose.x, a.pose.y);
  }
}

double CsvStreams::cross_track_rms() const {
  return truth_count_ ? std::sqrt(cross_track_sq_ / double(truth_count_)) : 0.0;
}

}  // namespace lidarloop
