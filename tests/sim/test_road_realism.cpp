// The ground as it is built, read back from the mesh and from noiseless scans: crown and grade,
// roughness of the ISO 8608 class, each curb profile's shape, ramps no steeper than 1:12, and the
// curb lines' kinds and cuts.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <numbers>

#include "sim/curb_band.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/polyline.hpp"
#include "sim/road_surface.hpp"
#include "sim/superelevation.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

const std::string kHeader = "name: test\norigin: {lat: 31.2856, lon: 121.2147}\n";

// Height of the mesh under (x, y), by a ray cast straight down.
double mesh_height(const RayScene& scene, double x, double y) {
  constexpr float kAbove = 100;
  RayHit hit;
  EXPECT_TRUE(scene.intersect({{float(x), float(y), kAbove}, {0, 0, -1}}, 0, 2 * kAbove, hit)) << x << ", " << y;
  return kAbove - hit.range;
}

TEST(RoadRealism, CrownAndGradeReadOffANoiselessScan) {
  // A road climbing the flank of a wide hill: at the hill's half radius its grade is
  // pi/2 * height / radius, with no curvature; its crown falls 3 % to each side.
  constexpr double kRadius = 2000, kHeight = 40, kCrossSlope = 0.03, kAt = kRadius / 2;
  const World w = test::world_from_yaml(
      kHeader + "geometry: {roughness_class: none}\nhills:\n  - {centre: [0, 0], radius: " + std::to_string(kRadius) +
      ", height: " + std::to_string(kHeight) + "}\nroads:\n  - {name: r, points: [[900, 0], [1100, 0]], width: 9, " +
      "cross_slope: " + std::to_string(kCrossSlope) + "}\n");
  const double grade = -std::numbers::pi / 2 * kHeight / kRadius;  // falling away from the hill's top
  RayScene scene(w.mesh);
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const LidarScanner scanner(config, test::materials());
  const Eigen::Isometry3d vehicle = rest_on_ground({kAt - 1.5, -2.25, 0}, w.pavement(), 2.7, 1.6);
  const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, 1);
  const Eigen::Isometry3d sensor = vehicle * config.mount();
  // Least squares plane z = a + b (x - kAt) + c y over the right half of the carriageway near kAt.
  std::vector<Eigen::Vector3d> ground;
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d q = sensor * Eigen::Vector3d(p.x, p.y, p.z);
    if (std::abs(q.x() - kAt) < 8 && q.y() < -0.5 && q.y() > -4.0) ground.push_back(q);
  }
  ASSERT_GT(ground.size(), 200u);
  Eigen::MatrixXd A(ground.size(), 3);
  Eigen::VectorXd z(ground.size());
  for (size_t i = 0; i < ground.size(); ++i) {
    A.row(long(i)) << 1, ground[i].x() - kAt, ground[i].y();
    z(long(i)) = ground[i].z();
  }
  const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(z);
  EXPECT_NEAR(plane(1), grade, 0.001);        // the grade, within 0.1 %
  EXPECT_NEAR(plane(2), kCrossSlope, 0.001);  // rising towards the crown, within 0.1 %
}

TEST(RoadRealism, RoughnessHasTheRmsOfItsIsoClass) {
  // ISO 8608: G(n) = G(n0) (n / n0)^-2, so the variance between n_lo and n_hi is G(n0) n0^2 (1/n_lo - 1/n_hi).
  for (char road_class : {'A', 'C'}) {
    const WorldDescription d = parse_world_description(
        kHeader + "geometry: {roughness_class: " + std::string(1, road_class) +
            ", roughness_min_wavelength: 0.5, roughness_max_wavelength: 10}\nroads:\n  - {name: r, points: [[0, 0], "
            "[10, 0]]}\n",
        "w.yaml");
    const RoadSurface surface(d);
    const double expected = std::sqrt(iso8608_psd(road_class) * 0.01 * (10 - 0.5));
    double sum2 = 0;
    int n = 0;
    for (double x = -500; x < 500; x += 1.7)
      for (double y = -500; y < 500; y += 1.9) sum2 += std::pow(surface.roughness({x, y}), 2), ++n;
    EXPECT_NEAR(std::sqrt(sum2 / n), expected, 0.1 * expected) << road_class;
  }
  EXPECT_EQ(iso8608_psd('B'), 64e-6);
}

// The simulation finds the wheels' contact at each 1 ms integration step and interpolates it for the
// firings between. At 30 m/s on the roughest class (D) with 0.5 m its shortest wave, a step is 3 cm:
// the interpolated pose must move a return at the HDL-32E's 100 m range by less than half its range
// noise (2 cm, 1 sigma) from where resting the car there puts it.
TEST(RoadRealism, GroundContactInterpolatedOverAStepIsTheRestingPose) {
  const WorldDescription d = parse_world_description(
      kHeader +
          "geometry: {roughness_class: D, roughness_min_wavelength: 0.5, roughness_max_wavelength: 10}\n"
          "roads:\n  - {name: r, points: [[0, 0], [10, 0]]}\n",
      "w.yaml");
  const RoadSurface surface(d);
  const GroundHeight ground = [&](const Eigen::Vector2d& p) { return surface.roughness(p); };
  constexpr double kWheelbase = 2.7, kTrack = 1.6, kStep = 30.0 * 1e-3;  // m: 30 m/s for 1 ms
  double worst_m = 0, worst_rad = 0;
  for (int k = 0; k < 2000; ++k) {
    const double yaw = 0.37 * k;
    const Pose2d a{0.61 * k, -0.43 * k, yaw}, b{a.x + kStep * std::cos(yaw), a.y + kStep * std::sin(yaw), yaw};
    const GroundContact ca = ground_contact(a, ground, kWheelbase, kTrack);
    const GroundContact cb = ground_contact(b, ground, kWheelbase, kTrack);
    for (double f : {0.25, 0.5, 0.75}) {
      const Pose2d p{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), yaw};
      const Eigen::Isometry3d interpolated = on_ground(
          p, {ca.z + f * (cb.z - ca.z), ca.pitch + f * (cb.pitch - ca.pitch), ca.roll + f * (cb.roll - ca.roll)});
      const Eigen::Isometry3d resting = rest_on_ground(p, ground, kWheelbase, kTrack);
      worst_m = std::max(worst_m, (interpolated.translation() - resting.translation()).norm());
      worst_rad = std::max(worst_rad, Eigen::AngleAxisd(interpolated.linear().transpose() * resting.linear()).angle());
    }
    // At the step itself the two halves are rest_on_ground, to the bit.
    ASSERT_TRUE(on_ground(a, ca).isApprox(rest_on_ground(a, ground, kWheelbase, kTrack), 0.0));
  }
  constexpr double kMaxRange = 100, kHalfRangeNoise = 0.01;  // m
  EXPECT_LT(worst_m + worst_rad * kMaxRange, kHalfRangeNoise);
  EXPECT_GT(worst_m, 0.0);  // the roughness is there to interpolate
  RecordProperty("worst_mm", std::to_string(worst_m * 1e3));
  RecordProperty("worst_deg", std::to_string(worst_rad * 180 / std::numbers::pi));
}

// A straight road along x with the curb on its right at y = -4 and the given curb keys.
struct CurbCase {
  std::string keys;
  CurbProfile profile;
  double height, gutter_width, gutter_slope;
};

TEST(RoadRealism, EachCurbProfileHasItsShapeInTheMesh) {
  for (const CurbCase& c :
       {CurbCase{"curb_profile: vertical, curb_height: 0.15", CurbProfile::vertical, 0.15, 0, 0},
        CurbCase{"curb_profile: sloped, curb_height: 0.12, gutter_width: 0.45, gutter_slope: 0.08", CurbProfile::sloped,
                 0.12, 0.45, 0.08},
        CurbCase{"curb_profile: rolled, curb_height: 0.10, gutter_width: 0.6", CurbProfile::rolled, 0.10, 0.6, 0.06}}) {
    SCOPED_TRACE(c.keys);
    const World w = test::world_from_yaml(
        kHeader + "geometry: {roughness_class: none}\nroads:\n  - {name: r, points: [[0, 0], [100, 0]], width: 8, " +
        c.keys + "}\n");
    RayScene scene(w.mesh);
    constexpr double kX = 50, kCurbY = -4;
    const double pavement_at_lip = w.surface->carriageway({kX, kCurbY + c.gutter_width});
    const double foot = pavement_at_lip - c.gutter_slope * c.gutter_width;
    // The gutter falls from its lip to the curb at its slope; before it the crowned pavement.
    EXPECT_NEAR(mesh_height(scene, kX, kCurbY + c.gutter_width + 0.3),
                w.surface->carriageway({kX, kCurbY + c.gutter_width + 0.3}), 0.005);
    if (c.gutter_width > 0) {
      EXPECT_NEAR(mesh_height(scene, kX, kCurbY + c.gutter_width / 2), foot + c.gutter_slope * c.gutter_width / 2,
                  0.01);
    }
    const double run = face_run(c.profile, c.height);
    // Up the face (towards -y, away from the road), then the top.
    for (double u : {0.25, 0.5, 0.75}) {
      if (run == 0) break;
      EXPECT_NEAR(mesh_height(scene, kX, kCurbY - run * u), foot + c.height * face_rise(c.profile, u), 0.01) << u;
    }
    EXPECT_NEAR(mesh_height(scene, kX, kCurbY - run - 0.05), foot + c.height, 0.01);
    EXPECT_NEAR(mesh_height(scene, kX, kCurbY + 0.01), foot, 0.01);
  }
  EXPECT_NEAR(face_rise(CurbProfile::rolled, 0.5), 0.5, 1e-12);
  EXPECT_NEAR(face_rise(CurbProfile::rolled, 0.25), (1 - std::cos(std::numbers::pi / 4)) / 2, 1e-12);
}

TEST(RoadRealism, CurbRampsAtCrosswalksAreNoSteeperThanOneInTwelve) {
  const World w = test::world_from_yaml(
      kHeader + "geometry: {roughness_class: none}\nroads:\n  - {name: r, points: [[0, 0], [100, 0]], width: 8, " +
      "curb_height: 0.15, sidewalk_width: 3}\ncrosswalks:\n  - {road: r, at: 50, width: 4}\n");
  RayScene scene(w.mesh);
  // Across the ramp's middle, from the road (y = -4) into the sidewalk: the slope of every 10 cm.
  double steepest = 0, previous = mesh_height(scene, 50, -4.2);
  for (double y = -4.3; y > -7.0; y -= 0.1) {
    const double z = mesh_height(scene, 50, y);
    steepest = std::max(steepest, std::abs(z - previous) / 0.1);
    previous = z;
  }
  EXPECT_LE(steepest, 1.0 / 12 + 1e-3);
  // The ramp reaches the level of the uncut sidewalk behind it.
  EXPECT_NEAR(mesh_height(scene, 50, -6.9), mesh_height(scene, 20, -6.9), 0.005);
  // Beside the cut the curb stands full height; at its middle it is flush with the road.
  EXPECT_NEAR(mesh_height(scene, 20, -4.05) - mesh_height(scene, 20, -3.95), 0.15, 0.01);
  EXPECT_NEAR(mesh_height(scene, 50, -4.05) - mesh_height(scene, 50, -3.95), 0.0, 0.01);
}

TEST(RoadRealism, CurbLinesNameTheirKindsAndCuts) {
  const World w = test::world_from_yaml(
      kHeader + "roads:\n  - {name: r, points: [[0, 0], [200, 0]], width: 8, curb_profile: sloped, " +
      "driveway_spacing: 50, driveway_width: 5}\ncrosswalks:\n  - {road: r, at: 100, width: 4}\n" +
      "curb_cuts:\n  - {road: r, at: 130, side: left, length: 20, kind: flush}\n");
  ASSERT_EQ(w.curbs.size(), w.curb_kinds.size());
  std::map<std::string, std::vector<double>> lengths;
  for (size_t i = 0; i < w.curbs.size(); ++i) lengths[w.curb_kinds[i]].push_back(polyline_length(w.curbs[i]));
  // Driveways at 25, 75, 125, 175 on both sides, except where the crosswalk's ramps and the lay-by are.
  ASSERT_EQ(lengths["ramp"].size(), 2u);  // one each side of the crosswalk
  for (double l : lengths["ramp"]) EXPECT_NEAR(l, 4.0, 0.6);
  ASSERT_EQ(lengths["flush"].size(), 1u);
  EXPECT_NEAR(lengths["flush"][0], 20.0, 0.6);
  EXPECT_EQ(lengths["driveway"].size(), 7u);  // 8 less the one the lay-by covers
  for (double l : lengths["driveway"]) EXPECT_NEAR(l, 5.0, 0.6);
  EXPECT_FALSE(lengths["sloped"].empty());
  EXPECT_TRUE(lengths["vertical"].empty());
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

TEST(RoadRealism, CurvesAreBankedOnlyWhereTheirDesignSpeedNeedsIt) {
  // AASHTO's low-speed method: V^2 / (127 R) - f. A 40 m curve needs nothing at 30 km/h (0.177 < 0.28)
  // and more than the 4 % cap at 50 km/h (0.49 - 0.19); a bank below the crown's slope is raised to it.
  EXPECT_EQ(superelevation_rate(40, 30, 0.02, 0.04), 0.0);
  EXPECT_DOUBLE_EQ(superelevation_rate(40, 50, 0.02, 0.04), 0.04);
  EXPECT_DOUBLE_EQ(superelevation_rate(95, 50, 0.02, 0.04), 0.02);  // 0.207 - 0.19 = 0.017 < 0.02
  EXPECT_EQ(superelevation_rate(40, 50, 0.02, 0.0), 0.0);
}

TEST(RoadRealism, ACurveIsBankedTowardsItsInsideAndRunsOffAtTheMaximumRelativeGradient) {
  // A left-hand quarter turn of 60 m radius at 50 km/h between two 200 m straights: the bank is the
  // 4 % cap through the arc, the normal 2 % crown on the straights far from it, and the pavement edge
  // climbs relative to the centreline at most at AASHTO's 0.65 % between them.
  constexpr double kRadius = 60, kHalfWidth = 4.5, kCross = 0.02, kCap = 0.04;
  const World w = test::world_from_yaml(kHeader +
                                        "geometry: {roughness_class: none}\nroads:\n  - {name: r, points: [[-200, 0], "
                                        "[100, 0], [100, 300]], width: 9, design_speed: 50, smoothing_radius: " +
                                        std::to_string(kRadius) + "}\n");
  const GroundHeight ground = w.pavement();
  // Mid-arc: the centre of the fillet is (100 - R, R); its mid-point lies at 45 deg.
  const Eigen::Vector2d centre(100 - kRadius, kRadius), radial(std::sqrt(0.5), -std::sqrt(0.5));
  const Eigen::Vector2d mid = centre + kRadius * radial;
  auto across = [&](const Eigen::Vector2d& at, const Eigen::Vector2d& outward, double l) {
    return ground(at + l * outward) - ground(at);
  };
  // Inside (towards the centre) falls at the cap, the outside rises at it.
  EXPECT_NEAR(across(mid, -radial, 4.0) / 4.0, -kCap, 0.001);
  EXPECT_NEAR(across(mid, radial, 4.0) / 4.0, kCap, 0.001);
  // Far along the first straight: the normal crown on both sides.
  EXPECT_NEAR(across({-150, 0}, {0, 1}, 4.0) / 4.0, -kCross, 0.001);
  EXPECT_NEAR(across({-150, 0}, {0, -1}, 4.0) / 4.0, -kCross, 0.001);
  // The outer edge's height relative to the centreline along the straight into the curve.
  const double gradient = max_relative_gradient(50);
  // Over 5 m: the bank is held per 0.5 m centreline sample, so shorter differences see its steps.
  constexpr double kBase = 5.0;
  double steepest = 0;
  for (double x = -100; x + kBase <= 100 - kRadius; x += 0.5) {
    const double rise = across({x + kBase, 0}, {0, -1}, kHalfWidth) - across({x, 0}, {0, -1}, kHalfWidth);
    steepest = std::max(steepest, std::abs(rise) / kBase);
  }
  EXPECT_GT(steepest, 0.5 * gradient);   // it does run off along here
  EXPECT_LE(steepest, gradient * 1.05);  // and no steeper than allowed
}

}  // namespace
}  // namespace lidarloop
