// The localizer as a whole, on a synthetic straight road whose truth is known exactly: curbs at
// y = +-4.5 m (15 cm high), a dashed centre line and zebra crossings in the intensity layer. The GPS
// is biased by a known offset; the curbs must remove its lateral part and the paint its longitudinal
// part. Then the bad days: NaN points, empty scans, no curbs, a minute without GPS, CAN gaps; and
// the per-stage timing of a scan.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <thread>

#include <unistd.h>

#include <gtest/gtest.h>

#include "localizer/localizer.hpp"
#include "localizer/stage_timer.hpp"

namespace lidarloop {
namespace {

constexpr double kCurbY = 4.5, kCurbHeight = 0.15, kMountHeight = 1.8, kMountX = 1.0;
constexpr double kSpeed = 10.0;  // m/s along +x
constexpr int64_t kScanNs = 100'000'000, kCanNs = 10'000'000, kGpsNs = 100'000'000;
const Geodetic kOrigin{48.0, 11.0, 500.0};

// Paint: the dashed centre line (0.2 m wide, 3 m dashes every 9 m) and a zebra crossing every 60 m
// (4 m deep, 0.5 m stripes across the road).
double reflectivity(double x, double y) {
  constexpr double kPaint = 70, kAsphalt = 12;
  const double dash = std::fmod(x + 1000.0, 9.0), crossing = std::fmod(x + 1000.0, 60.0);
  if (std::abs(y) < 0.1 && dash < 3.0) return kPaint;
  if (crossing < 4.0 && std::fmod(y + 100.0, 1.0) < 0.5) return kPaint;
  return kAsphalt;
}

HdMap synthetic_map() {
  CurbMap curbs{kOrigin, "synthetic", {{{-200, kCurbY}, {800, kCurbY}}, {{-200, -kCurbY}, {800, -kCurbY}}}, {}};
  IntensityMapHeader header;
  header.world = "synthetic";
  header.origin = kOrigin;
  IntensityMapBuilder builder(header);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0, 2.0);
  for (double x = -100; x < 700; x += 0.1)
    for (double y = -kCurbY; y <= kCurbY; y += 0.1) builder.add({x, y}, reflectivity(x, y) + noise(rng));
  // One folder per process: CTest runs the test cases as parallel processes.
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("lidarloop_test_localizer_map_" + std::to_string(getpid()))).string();
  builder.save(dir);
  return HdMap{CurbLayer(curbs), IntensityMap(dir), std::nullopt};
}

// A 10 Hz scan of 16 downward lasers from a car driving along y = lateral at kSpeed, each point cast
// from the sensor's position at its own firing time (so de-skew has real distortion to remove).
PointCloud synthetic_scan(int64_t stamp_ns, double x0, double lateral, std::mt19937_64& rng, int azimuth_steps = 900) {
  PointCloud cloud;
  cloud.stamp_ns = stamp_ns;
  std::normal_distribution<double> noise(0, 0.01);
  const double step_ns = double(kScanNs) / azimuth_steps;
  for (int a = 0; a < azimuth_steps; ++a) {
    const double azimuth = -2 * M_PI * a / azimuth_steps;  // clockwise, like the HDL-32E
    const auto t_ns = uint32_t(a * step_ns);
    const double sx = x0 + kSpeed * t_ns * 1e-9 + kMountX;  // sensor position, world
    for (int ring = 0; ring < 16; ++ring) {
      const double elevation = (-30.67 + 1.333 * ring) * M_PI / 180;
      const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                std::sin(elevation));
      // Ray against the road plane; beyond the curb, against the sidewalk plane; in between, the face.
      double t = kMountHeight / -dir.z();
      double y = lateral + t * dir.y();
      if (std::abs(y) > kCurbY) {
        const double t_walk = (kMountHeight - kCurbHeight) / -dir.z();
        const double t_face = (std::copysign(kCurbY, y) - lateral) / dir.y();
        t = std::abs(lateral + t_walk * dir.y()) > kCurbY ? t_walk : t_face;
        if (t == t_face) t = std::max(t_face, 0.0);
        y = lateral + t * dir.y();
      }
      if (t > 60) continue;
      const Eigen::Vector3d p = dir * (t + noise(rng));
      const double wx = sx + t * dir.x();
      LidarPoint q;
      q.x = float(p.x()), q.y = float(p.y()), q.z = float(p.z());
      q.intensity = uint8_t(std::clamp(reflectivity(wx, y), 0.0, 100.0));
      q.ring = uint16_t(ring);
      q.t_ns = t_ns;
      cloud.points.push_back(q);
    }
  }
  return cloud;
}

LocalizerParams test_params() {
  LocalizerParams p;
  p.lidar_mount = Eigen::Translation3d(kMountX, 0, kMountHeight) * Eigen::Isometry3d::Identity();
  p.health.min_scan_points = 500;
  return p;
}

struct DriveOptions {
  double duration_s = 6;
  Eigen::Vector2d gps_bias{-1.5, 1.2};  // m, east and north: the known offset to remove
  std::function<Eigen::Vector2d(int64_t)> gps_jump = [](int64_t) { return Eigen::Vector2d::Zero(); };  // added
  double lateral = -2.0;  // the car's true y (right-hand lane)
  int azimuth_steps = 900;
  std::function<bool(int64_t)> gps_up = [](int64_t) { return true; };
  std::function<bool(int64_t)> can_up = [](int64_t) { return true; };
  std::function<void(PointCloud&, int64_t)> corrupt = [](PointCloud&, int64_t) {};
};

// Drives the synthetic road and returns every scan's estimate with the truth at its stamp.
std::vector<std::pair<LocalizerEstimate, Pose2d>> drive(Localizer& localizer, const DriveOptions& o) {
  const LocalFrame frame(kOrigin);
  std::mt19937_64 rng(11);
  std::vector<std::pair<LocalizerEstimate, Pose2d>> out;
  const int64_t end = int64_t(o.duration_s * 1e9);
  int64_t scan_start = 0;
  for (int64_t t = 0; t <= end; t += kCanNs) {
    const Pose2d truth{kSpeed * t * 1e-9, o.lateral, 0};
    if (o.can_up(t)) {
      CanFrame f;
      f.stamp_ns = t;
      f.wheel_speed_mps = {kSpeed, kSpeed, kSpeed, kSpeed};
      localizer.on_can(f);
    }
    if (t % kGpsNs == 0 && o.gps_up(t)) {
      GpsFix g;
      g.stamp_ns = t;
      g.status = GpsStatus::fix;
      const Geodetic ll = frame.to_geodetic(Eigen::Vector2d(truth.x, truth.y) + o.gps_bias + o.gps_jump(t));
      g.lat_deg = ll.lat_deg, g.lon_deg = ll.lon_deg;
      g.heading_rad = 0.02;
      g.position_covariance[0] = g.position_covariance[4] = 4.0;
      g.heading_variance = 0.03 * 0.03;
      localizer.on_gps(g);
    }
    if (t > 0 && t % kScanNs == 0) {
      PointCloud scan = synthetic_scan(scan_start, kSpeed * scan_start * 1e-9, o.lateral, rng, o.azimuth_steps);
      o.corrupt(scan, scan_start);
      const LocalizerEstimate e = localizer.on_scan(scan);
      out.emplace_back(e, Pose2d{kSpeed * e.stamp_ns * 1e-9, o.lateral, 0});
      scan_start = t;
    }
  }
  return out;
}

bool finite(const LocalizerEstimate& e) {
  return std::isfinite(e.pose.x) && std::isfinite(e.pose.y) && std::isfinite(e.pose.yaw) && e.covariance.allFinite();
}

HdMap& shared_map() {
  static HdMap map = synthetic_map();
  return map;
}

TEST(Localizer, CurbsAndPaintRemoveAKnownGpsOffset) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.duration_s = 8;  // past the crossing at x = 60
  const auto run = drive(localizer, o);
  ASSERT_FALSE(run.empty());
  const auto& [e, truth] = run.back();
  std::cout << "[ figures  ] after " << run.size() << " scans with GPS off by (-1.5, 1.2) m: error ("
            << e.pose.x - truth.x << ", " << e.pose.y - truth.y << ") m, " << (e.pose.yaw - truth.yaw) * 180 / M_PI
            << " deg; status " << describe_health(e.health) << "\n";
  EXPECT_NEAR(e.pose.y, truth.y, 0.05);  // lateral: the curbs
  EXPECT_NEAR(e.pose.x, truth.x, 0.2);   // longitudinal: the paint (one cell is 0.2 m)
  EXPECT_NEAR(e.pose.yaw, truth.yaw, 0.3 * M_PI / 180);
  EXPECT_EQ(e.health, 0u) << describe_health(e.health);
  // The curb match says nothing along the road: its observation must not have pulled x alone.
  EXPECT_GT(e.curb_features, 30u);
}

TEST(Localizer, GpsOnlyMethodKeepsTheGpsOffset) {
  LocalizerParams p = test_params();
  p.method = LocalizerMethod::gps;
  Localizer localizer(shared_map(), p);
  const auto run = drive(localizer, {});
  const auto& [e, truth] = run.back();
  EXPECT_GT(std::hypot(e.pose.x - truth.x, e.pose.y - truth.y), 1.0);  // nothing removes the bias
}

TEST(Localizer, GicpWithoutAPointLayerSaysSoAndKeepsTheFilterGoing) {
  // This map has no point-cloud layer (a map folder of format 4 or older): gicp has nothing to match,
  // flags every scan and carries on with CAN and GPS.
  LocalizerParams p = test_params();
  p.method = LocalizerMethod::gicp;
  Localizer localizer(shared_map(), p);
  DriveOptions o;
  o.duration_s = 2;
  const auto run = drive(localizer, o);
  ASSERT_FALSE(run.empty());
  for (const auto& [e, truth] : run) {
    ASSERT_TRUE(finite(e));
    if (!(e.health & kNotInitialized)) {
      EXPECT_TRUE(e.health & kNoPointMatch) << describe_health(e.health);
    }
  }
  EXPECT_NE(describe_health(kNoPointMatch | kPointMatchRejected).find("point match rejected"), std::string::npos);
}

TEST(Localizer, NoPoseBeforeTheFirstFix) {
  Localizer localizer(shared_map(), test_params());
  std::mt19937_64 rng(1);
  const LocalizerEstimate e = localizer.on_scan(synthetic_scan(0, 0, -2, rng));
  EXPECT_TRUE(e.health & kNotInitialized);
  EXPECT_TRUE(finite(e));
  EXPECT_FALSE(localizer.pose().has_value());
}

TEST(Localizer, NonFinitePointsAreDroppedAndReported) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.corrupt = [](PointCloud& c, int64_t) {
    for (size_t i = 0; i < c.points.size(); i += 7) c.points[i].x = (i % 2) ? NAN : INFINITY;
  };
  const auto run = drive(localizer, o);
  for (const auto& [e, truth] : run) {
    ASSERT_TRUE(finite(e));
    EXPECT_TRUE(e.health & kInvalidPoints);
    EXPECT_GT(e.dropped_points, 0u);
  }
  EXPECT_NEAR(run.back().first.pose.y, run.back().second.y, 0.05);
}

TEST(Localizer, EmptyScansAndScansWithoutCurbsDegradeWithoutJumping) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  // From 3 s on: every other scan empty, the others with everything beyond 3 m of the car removed
  // (no curb in sight, as when a bus hides them).
  o.corrupt = [](PointCloud& c, int64_t stamp) {
    if (stamp < 3'000'000'000) return;
    if ((stamp / kScanNs) % 2) {
      c.points.clear();
      return;
    }
    std::erase_if(c.points, [](const LidarPoint& p) { return std::hypot(p.x, p.y) > 3.0; });
  };
  const auto run = drive(localizer, o);
  double settled_variance = 0;
  for (size_t i = 1; i < run.size(); ++i) {
    const auto& [e, truth] = run[i];
    ASSERT_TRUE(finite(e));
    if (e.stamp_ns < 2'900'000'000) {
      settled_variance = e.covariance(1, 1);
      continue;
    }
    if (e.stamp_ns < 3'100'000'000) continue;
    EXPECT_TRUE(e.health & (kEmptyScan | kFewCurbs)) << describe_health(e.health);
    // No jump: between scans the estimate moves as the car does, give or take what 10 fixes of a GPS
    // that is 1.9 m off can pull it (it is all the filter hears now; it drifts, it does not jump).
    const LocalizerEstimate& previous = run[i - 1].first;
    const double moved_x = e.pose.x - previous.pose.x, moved_y = e.pose.y - previous.pose.y;
    EXPECT_NEAR(moved_x, kSpeed * double(e.stamp_ns - previous.stamp_ns) * 1e-9, 0.1);
    EXPECT_NEAR(moved_y, 0.0, 0.1);
  }
  EXPECT_GT(run.back().first.covariance(1, 1), 4 * settled_variance);  // and it says it is less sure
}

TEST(Localizer, AMinuteWithoutGpsIsReportedAndSurvived) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.duration_s = 65;
  o.azimuth_steps = 300;  // a long drive: sparse scans keep it quick (still ~100 curb points a scan)
  o.gps_up = [](int64_t t) { return t < 3'000'000'000; };
  const auto run = drive(localizer, o);
  for (const auto& [e, truth] : run) ASSERT_TRUE(finite(e));
  const auto& [e, truth] = run.back();
  EXPECT_TRUE(e.health & kNoGps);
  // Between crossings the dashes alone may not be enough for APS (rejected, unusable or as wide as its
  // window); nothing else may be wrong.
  EXPECT_EQ(e.health & ~uint32_t(kNoGps | kIntensityMatchRejected | kNoIntensityMatch | kIntensityAmbiguous), 0u)
      << describe_health(e.health);
  std::cout << "[ figures  ] after 62 s without GPS: error (" << e.pose.x - truth.x << ", " << e.pose.y - truth.y
            << ") m\n";
  EXPECT_NEAR(e.pose.y, truth.y, 0.05);
  EXPECT_NEAR(e.pose.x, truth.x, 0.3);
}

TEST(Localizer, CanGapsAreReportedAndInflateTheCovariance) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.can_up = [](int64_t t) { return t < 3'000'000'000 || t > 4'000'000'000; };
  const auto run = drive(localizer, o);
  bool saw_gap = false;
  for (const auto& [e, truth] : run) {
    ASSERT_TRUE(finite(e));
    if (e.stamp_ns > 3'150'000'000 && e.stamp_ns < 4'000'000'000) {
      EXPECT_TRUE(e.health & kCanGap);
      saw_gap = true;
      EXPECT_LT(std::abs(e.pose.y - truth.y), 0.1);
    }
  }
  EXPECT_TRUE(saw_gap);
  EXPECT_FALSE(run.back().first.health & kCanGap);
}

TEST(StageTimer, AddsTheScopesWallTimeToItsField) {
  double ms = 5.0;  // a stage run in pieces sums up
  {
    const StageTimer timer(ms);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_GE(ms, 7.0);
}

TEST(Localizer, EveryStageIsTimedWithinTheScansTotal) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.duration_s = 2;
  const auto run = drive(localizer, o);
  ASSERT_FALSE(run.empty());
  for (const auto& [e, truth] : run) {
    double stages = 0;
    for (double ms : e.stage_ms) stages += ms;
    EXPECT_LE(stages, e.total_ms + 1e-6);  // the stages do not overlap
  }
  const LocalizerEstimate& last = run.back().first;
  ASSERT_EQ(last.health, 0u) << describe_health(last.health);
  for (int s = 0; s < kStageCount; ++s)  // the proposed method runs them all, but gicp's
    if (Stage(s) != Stage::point_matching) {
      EXPECT_GT(last.stage_ms[size_t(s)], 0.0) << stage_name(Stage(s));
    }
}

TEST(LocalizerParams, ReadsOverridesAndRejectsUnknownKeys) {
  LocalizerParams p;
  const YamlReader y = YamlReader::from_string(
      "localizer:\n  method: m-icp\n  probabilistic_icp: {n_t: 12, global: {max_iterations: 5}}\n  deskew: false\n",
      "s.yaml");
  read_localizer_params(y, y.root()["localizer"], p);
  EXPECT_EQ(p.method, LocalizerMethod::m_icp);
  EXPECT_EQ(p.probabilistic_icp.n_t, 12);
  EXPECT_EQ(p.probabilistic_icp.global.max_iterations, 5);
  EXPECT_FALSE(p.deskew);
  const YamlReader bad = YamlReader::from_string("localizer:\n  aps: {alpha: 0.5, alpah: 2}\n", "bad.yaml");
  try {
    read_localizer_params(bad, bad.root()["localizer"], p);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2:21: unknown key 'alpah'"), std::string::npos) << e.what();
  }
  const YamlReader gicp = YamlReader::from_string(
      "localizer:\n  method: gicp\n  gicp: {scan_voxel_m: 0.8, max_iterations: 12, min_fitness: 0.4}\n", "g.yaml");
  read_localizer_params(gicp, gicp.root()["localizer"], p);
  EXPECT_EQ(p.method, LocalizerMethod::gicp);
  EXPECT_EQ(p.gicp.scan_voxel_m, 0.8);
  EXPECT_EQ(p.gicp.max_iterations, 12);
  EXPECT_EQ(p.gicp.min_fitness, 0.4);
  EXPECT_FALSE(removes_obstacles(LocalizerMethod::gicp));
  const YamlReader bad_gicp = YamlReader::from_string("localizer:\n  gicp: {voxel: 0.5}\n", "bg.yaml");
  EXPECT_THROW(read_localizer_params(bad_gicp, bad_gicp.root()["localizer"], p), InputError);
  const YamlReader method = YamlReader::from_string("localizer: {method: magic}\n", "m.yaml");
  EXPECT_THROW(read_localizer_params(method, method.root()["localizer"], p), InputError);
}

// A fix is the antenna's position. Driving straight at 60 deg with exact fixes of an antenna 1.5 m
// ahead and 0.3 m left of the rear axle: configured with that lever arm, KF1's rear axle is the true
// one to within 1 cm; configured without it, the estimate is off by the arm (the test can fail).
// A multipath jump of 4 m along the road, once the GPS's level is known (from 3 s to 5 s), or already
// there when the drive starts (until 3 s). Either way the map holds the car where it is.
bool gps_rejected_after(const std::vector<std::pair<LocalizerEstimate, Pose2d>>& run, double t_s) {
  for (const auto& [e, truth] : run)
    if (e.stamp_ns * 1e-9 > t_s && (e.health & kGpsRejected)) return true;
  return false;
}

TEST(LocalizerGps, AJumpAwayFromTheMapsPoseIsRejectedUntilItStepsBack) {
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.duration_s = 7;
  o.gps_jump = [](int64_t t) { return Eigen::Vector2d(t >= 3'000'000'000 && t < 5'000'000'000 ? 4.0 : 0.0, 0.0); };
  const auto run = drive(localizer, o);
  EXPECT_TRUE(gps_rejected_after(run, 3.5));
  EXPECT_FALSE(gps_rejected_after(run, 5.5));
  for (const auto& [e, truth] : run) {
    if (e.stamp_ns > 3'000'000'000) {
      EXPECT_LT(std::abs(e.pose.x - truth.x), 0.5) << e.stamp_ns;
    }
  }
}

TEST(LocalizerGps, AJumpThatEndsBeforeItsLevelWasKnownIsNotRejectedForever) {
  // The GPS starts 4 m off and steps back to its usual bias at 3 s: a step towards the map's pose.
  Localizer localizer(shared_map(), test_params());
  DriveOptions o;
  o.duration_s = 7;
  o.gps_jump = [](int64_t t) { return Eigen::Vector2d(t < 3'000'000'000 ? 4.0 : 0.0, 0.0); };
  const auto run = drive(localizer, o);
  EXPECT_FALSE(gps_rejected_after(run, 4.0));
}

TEST(LocalizerGps, TheConfiguredLeverArmIsTakenOffTheFixes) {
  HdMap map = synthetic_map();
  const LocalFrame frame(kOrigin);
  const Eigen::Vector3d arm{1.5, 0.3, 1.6};
  const double heading = 60 * M_PI / 180;
  constexpr int64_t kDriveNs = 10'000'000'000;
  auto final_error = [&](const Eigen::Vector3d& configured) {
    LocalizerParams p = test_params();
    p.method = LocalizerMethod::gps;
    p.gps_antenna = configured;
    Localizer localizer(map, p);
    Eigen::Vector2d truth{0, 0};
    for (int64_t t = 0; t <= kDriveNs; t += kCanNs) {
      truth = kSpeed * double(t) * 1e-9 * Eigen::Vector2d(std::cos(heading), std::sin(heading));
      CanFrame f;
      f.stamp_ns = t;
      f.wheel_speed_mps = {kSpeed, kSpeed, kSpeed, kSpeed};
      localizer.on_can(f);
      if (t % kGpsNs != 0) continue;
      GpsFix g;
      g.stamp_ns = t;
      g.status = GpsStatus::fix;
      const Geodetic ll = frame.to_geodetic(truth + Eigen::Rotation2Dd(heading) * arm.head<2>());
      g.lat_deg = ll.lat_deg, g.lon_deg = ll.lon_deg;
      g.heading_rad = heading;
      g.position_covariance[0] = g.position_covariance[4] = 4.0;
      g.heading_variance = 0.03 * 0.03;
      localizer.on_gps(g);
    }
    const Pose2d estimate = *localizer.pose();
    return (Eigen::Vector2d(estimate.x, estimate.y) - truth).norm();
  };
  const double with_arm = final_error(arm), without = final_error(Eigen::Vector3d::Zero());
  EXPECT_LT(with_arm, 0.01);
  EXPECT_GT(without, 0.9 * arm.head<2>().norm());
  RecordProperty("error_with_lever_arm_m", std::to_string(with_arm));
  RecordProperty("error_without_m", std::to_string(without));
}

}  // namespace
}  // namespace lidarloop
