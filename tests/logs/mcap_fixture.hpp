#pragma once
// A synthetic run for the MCAP tests (unit tests and the Node.js cross-check): every stream the
// simulator produces, with seeded random values, recorded through McapRecorder in the order the
// simulator emits them (a scan after the 100 ms it covers). Header-only, so both test programs share it.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "logs/mcap_recorder.hpp"

namespace lidarloop::test {

struct SyntheticEstimate {
  int64_t stamp_ns = 0;
  Pose2d pose;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  LocalizerStatus status;  // at stamp_ns
};

struct SyntheticRun {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  // The GPS antenna's lever arm: sim/gps_model.hpp's default (0.9 m ahead of the rear axle, 1.5 m up),
  // off every axis but y, so a tf that dropped, swapped or zeroed a component shows.
  Eigen::Vector3d gps_antenna{0.9, 0.0, 1.5};
  std::vector<TruthSample> truth;
  std::vector<CanFrame> can;
  std::vector<GpsFix> gps, rtk;
  std::vector<PointCloud> scans;
  std::vector<std::pair<int64_t, std::vector<ros2::ActorState>>> actors;
  std::vector<SyntheticEstimate> estimates;
  std::string scenario_yaml = "world: campus\nduration_s: 1\nseed: 7\n";
};

// Every field of two points equal, to the bit (a decoded cloud against the one encoded).
inline bool same_point(const LidarPoint& a, const LidarPoint& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.intensity == b.intensity && a.ring == b.ring && a.t_ns == b.t_ns;
}

inline GpsFix synthetic_fix(std::mt19937_64& rng, int64_t t, GpsStatus status) {
  std::uniform_real_distribution<double> u(-1, 1);
  GpsFix f;
  f.stamp_ns = t;
  f.status = status;
  f.lat_deg = 48.0 + 1e-4 * u(rng);
  f.lon_deg = 11.0 + 1e-4 * u(rng);
  f.alt_m = 500 + u(rng);
  for (double& c : f.position_covariance) c = u(rng);
  f.heading_rad = 3 * u(rng);
  f.heading_variance = 1e-3 * (2 + u(rng));
  return f;
}

// `seconds` of driving at the simulator's rates: truth and CAN 100 Hz, GPS and RTK 10 Hz, scans of
// `points` points at 10 Hz with their actors and an estimate.
inline SyntheticRun make_synthetic_run(double seconds, int points, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<float> coord(-80.f, 80.f);
  SyntheticRun run;
  run.mount.translation() = Eigen::Vector3d(1.2, 0.0, 1.9);
  run.mount.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const int64_t step = 10'000'000, end = int64_t(seconds * 1e9);
  for (int64_t t = step; t <= end; t += step) {
    TruthSample s{t,
                  {0.5 * double(t) * 1e-9 * 10, 2 + u(rng), 0.1 * u(rng)},
                  10 + u(rng),
                  0.01 * u(rng),
                  0.02 * u(rng),
                  0.05 * u(rng),
                  {0.01 * u(rng), 0.02 * u(rng), 0.02 * u(rng), {1.2, 0, 0.7}}};
    run.truth.push_back(s);
    CanFrame c;
    c.stamp_ns = t + 2'000'000;  // bus latency: later than the truth of the same step
    for (double& w : c.wheel_speed_mps) w = 10 + 0.1 * u(rng);
    c.steering_wheel_angle_rad = 0.3 * u(rng);
    run.can.push_back(c);
    if (t % (10 * step) == 0) {
      run.gps.push_back(synthetic_fix(rng, t, GpsStatus::fix));
      run.rtk.push_back(synthetic_fix(rng, t, GpsStatus::rtk));
      PointCloud cloud;
      cloud.stamp_ns = t - 10 * step;
      for (int i = 0; i < points; ++i) {
        LidarPoint p;
        p.x = coord(rng);
        p.y = coord(rng);
        p.z = coord(rng) / 20;
        p.intensity = uint8_t(rng() % 256);
        p.ring = uint16_t(rng() % 32);
        p.t_ns = uint32_t(int64_t(i) * 99'999'999 / std::max(points - 1, 1));
        cloud.points.push_back(p);
      }
      run.scans.push_back(std::move(cloud));
      run.actors.push_back({t - 10 * step,
                            {{"bus_1", "bus", {u(rng) * 50, u(rng) * 50, u(rng)}},
                             {"walker", "pedestrian", {u(rng) * 50, u(rng) * 50, u(rng)}}}});
      SyntheticEstimate e;
      e.stamp_ns = t - 10 * step;
      e.pose = {s.pose.x + 0.1 * u(rng), s.pose.y + 0.1 * u(rng), s.pose.yaw + 0.01 * u(rng)};
      e.cov << 0.04, 0.01, 0.001, 0.01, 0.09, 0.002, 0.001, 0.002, 0.0004;
      // Every third estimate lost (unbounded, searching wide), the others degraded or not.
      LocalizerStatus& st = e.status;
      st.stamp_ns = e.stamp_ns;
      st.lost = run.estimates.size() % 3 == 2;
      st.wide_search = st.lost;
      st.health_flags = st.lost ? 1u << 14 : uint32_t(rng() % 2);
      st.level = st.lost ? ros2::kDiagnosticError : st.health_flags ? ros2::kDiagnosticWarn : ros2::kDiagnosticOk;
      st.health = st.lost ? "lost" : st.health_flags ? "no GPS" : "ok";
      if (!st.lost) {
        st.protection_lateral_m = 0.3 + 0.1 * u(rng);
        st.protection_longitudinal_m = 0.5 + 0.1 * u(rng);
      }
      run.estimates.push_back(e);
    }
  }
  return run;
}

// Records `run` in simulator order; the scenario goes in as an attachment, seed and version as metadata.
inline McapWriterStats record_synthetic_run(const SyntheticRun& run, const std::string& path,
                                            McapWriterOptions options = {}) {
  McapRecorder rec(path, run.mount, run.gps_antenna, std::move(options));
  rec.add_attachment("scenario.yaml", "application/yaml", run.scenario_yaml);
  rec.add_metadata("run", {{"seed", "7"}, {"version", "test"}, {"map_hash", "0123abcd"}});
  size_t gps = 0, scan = 0;
  for (size_t i = 0; i < run.truth.size(); ++i) {
    const int64_t t = run.truth[i].stamp_ns;
    rec.write_can(run.can[i]);
    rec.write_truth(run.truth[i]);
    if (gps < run.gps.size() && run.gps[gps].stamp_ns == t) {
      rec.write_gps(run.gps[gps]);
      rec.write_rtk(run.rtk[gps++]);
    }
    if (scan < run.scans.size() && run.scans[scan].stamp_ns + 100'000'000 == t) {
      rec.write_scan(run.scans[scan]);
      rec.write_actors(run.actors[scan].first, run.actors[scan].second);
      const auto& e = run.estimates[scan++];
      rec.write_estimate(e.status, e.pose, e.cov);
    }
  }
  rec.close();
  return rec.stats();
}

}  // namespace lidarloop::test
