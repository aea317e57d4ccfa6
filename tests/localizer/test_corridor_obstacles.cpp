// Driving corridor (section 2.1.1) on a hand-made T-intersection with known road and sidewalk areas,
// and obstacle rejection (section 2.1.2) against a known tilted ground plane with boxes on it.
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "localizer/driving_corridor.hpp"
#include "localizer/obstacle_rejection.hpp"

namespace lidarloop {
namespace {

void add_line(std::vector<Eigen::Vector2d>& out, Eigen::Vector2d a, Eigen::Vector2d b, double spacing = 0.1) {
  const int n = static_cast<int>(std::ceil((b - a).norm() / spacing));
  for (int i = 0; i <= n; ++i) out.push_back(a + (b - a) * (static_cast<double>(i) / n));
}

// A road 10 m wide along x (curbs at y = +-5) and a road 8 m wide going north from it (curbs at
// x = +-4), spaced like CurbLayer's points (0.1 m). The curbs run to +-80 m, past the grid edge from
// either test pose: a curb ending inside the grid would let the road's free space run round its end
// into the sidewalk, which is right (the corridor is what the curbs enclose) but not what is tested.
// The top curb's gap is [-4, 4] by default, the side road's width (see SlotAtCornerSealedUpToDilationWidth
// for wider gaps).
std::vector<Eigen::Vector2d> t_intersection(double top_gap_half = 4.0) {
  std::vector<Eigen::Vector2d> c;
  add_line(c, {-80, -5}, {80, -5});
  add_line(c, {-80, 5}, {-top_gap_half, 5});
  add_line(c, {top_gap_half, 5}, {80, 5});
  add_line(c, {-4, 5}, {-4, 80});
  add_line(c, {4, 5}, {4, 80});
  return c;
}

bool in_corridor(const DrivingCorridor& corridor, const Eigen::Vector2d& world) {
  return corridor.contains(world_to_vehicle(corridor.pose, world));
}

const std::vector<Eigen::Vector2d> kRoad = {{20, 0}, {-20, 0}, {0, 20}, {10, 0}, {0, 3}, {-2, 35}};
const std::vector<Eigen::Vector2d> kSidewalk = {{20, 8}, {-20, -8}, {10, 20}, {-10, 20}, {20, -8}};

TEST(DrivingCorridor, TIntersectionFromTheJunction) {
  const auto corridor = extract_driving_corridor(t_intersection(), Pose2d{0, 0, 0});
  ASSERT_EQ(corridor.mask.rows, 400);
  ASSERT_EQ(corridor.mask.cols, 400);
  ASSERT_EQ(corridor.mask.type(), CV_8U);
  for (const auto& p : kRoad) EXPECT_TRUE(in_corridor(corridor, p)) << p.transpose();
  for (const auto& p : kSidewalk) EXPECT_FALSE(in_corridor(corridor, p)) << p.transpose();
  // Vehicle frame directly: forward (x) is east here, left (y) is north.
  EXPECT_TRUE(corridor.contains({20, 0}));
  EXPECT_TRUE(corridor.contains({0, 20}));
  EXPECT_FALSE(corridor.contains({10, 20}));
  // Outside the +-40 m grid nothing is corridor.
  EXPECT_FALSE(corridor.contains({45, 0}));
  EXPECT_FALSE(corridor.contains({std::numeric_limits<double>::quiet_NaN(), 0}));
}

TEST(DrivingCorridor, FrameTransformWithRotatedVehicle) {
  // Heading north at (30, 0): the vehicle's forward is +y world, its left is -x world. Only points
  // within the +-40 m grid can be in it, so (-20, 0) and (-20, -8) (50 m away) are left out.
  const Pose2d pose{30, 0, std::numbers::pi / 2};
  const auto corridor = extract_driving_corridor(t_intersection(), pose);
  for (const auto& p : kRoad) {
    if ((world_to_vehicle(pose, p)).cwiseAbs().maxCoeff() >= 40) continue;
    EXPECT_TRUE(in_corridor(corridor, p)) << p.transpose();
  }
  for (const auto& p : kSidewalk) {
    if ((world_to_vehicle(pose, p)).cwiseAbs().maxCoeff() >= 40) continue;
    EXPECT_FALSE(in_corridor(corridor, p)) << p.transpose();
  }
  // The transform itself: world (20, 0) is 10 m to the vehicle's left; (30, 20) is 20 m ahead.
  EXPECT_NEAR(world_to_vehicle(pose, {20, 0}).x(), 0, 1e-12);
  EXPECT_NEAR(world_to_vehicle(pose, {20, 0}).y(), 10, 1e-12);
  EXPECT_NEAR(world_to_vehicle(pose, {30, 20}).x(), 20, 1e-12);
  EXPECT_NEAR(world_to_vehicle(pose, {30, 20}).y(), 0, 1e-12);
  // Heading north, world (30, 8) is 8 m straight ahead, beyond the curb at y = 5; (30, 3) is road.
  EXPECT_FALSE(corridor.contains({8, 0}));
  EXPECT_TRUE(corridor.contains({3, 0}));
}

TEST(DrivingCorridor, DilationShrinksCorridorNearCurbs) {
  // r = 2 cells = 0.4 m: cells within 0.4 m of the curb at y = -5 are lost, cells 0.6 m away are kept.
  const auto corridor = extract_driving_corridor(t_intersection(), Pose2d{0, 0, 0});
  EXPECT_TRUE(in_corridor(corridor, {20, -4.3}));
  EXPECT_FALSE(in_corridor(corridor, {20, -4.75}));
  CorridorParams no_dilation;
  no_dilation.dilation_cells = 0;
  const auto thin = extract_driving_corridor(t_intersection(), Pose2d{0, 0, 0}, no_dilation);
  EXPECT_TRUE(in_corridor(thin, {20, -4.75}));
  EXPECT_GT(cv::countNonZero(thin.mask), cv::countNonZero(corridor.mask));
}

TEST(DrivingCorridor, DilationSealsThinBreakInCurb) {
  // A 0.5 m break in the south curb (a driveway drawn as a gap): without dilation the road leaks into
  // the sidewalk behind it; with the default r = 2 it is sealed.
  std::vector<Eigen::Vector2d> curbs;
  for (const auto& p : t_intersection())
    if (!(p.y() == -5 && p.x() > 10 && p.x() < 10.5)) curbs.push_back(p);
  EXPECT_FALSE(in_corridor(extract_driving_corridor(curbs, Pose2d{0, 0, 0}), {20, -8}));
  CorridorParams no_dilation;
  no_dilation.dilation_cells = 0;
  EXPECT_TRUE(in_corridor(extract_driving_corridor(curbs, Pose2d{0, 0, 0}, no_dilation), {20, -8}));
}

TEST(DrivingCorridor, VehicleOnCurbUsesNearestFreeCell) {
  // The vehicle's cell is inside the dilated curb at y = -5 (pose error, or hugging the curb): the
  // road side is nearer than the sidewalk side (0.45 m vs 0.55 m past the curb line), so the corridor is the road.
  const auto corridor = extract_driving_corridor(t_intersection(), Pose2d{20, -4.95, 0});
  ASSERT_FALSE(corridor.mask.empty());
  EXPECT_EQ(corridor.mask.at<std::uint8_t>(200, 200), 0);  // the vehicle's own cell is not corridor
  EXPECT_TRUE(in_corridor(corridor, {0, 0}));
  EXPECT_TRUE(in_corridor(corridor, {0, 20}));
  EXPECT_FALSE(in_corridor(corridor, {20, -8}));
}

TEST(DrivingCorridor, SlotAtCornerSealedUpToDilationWidth) {
  // A top-curb gap of [-5, 5] against side-road curbs at x = +-4 leaves 1 m slots at the
  // junction's corners: curb cells 5 apart, 4 free cells between, just closed by r = 2 on each side.
  // A 1.4 m slot is not: the corridor then runs into the sidewalk behind. It is only as closed as
  // the map's curbs (plus the dilation).
  auto corridor = extract_driving_corridor(t_intersection(5.0), Pose2d{0, 0, 0});
  EXPECT_FALSE(in_corridor(corridor, {10, 20}));
  EXPECT_FALSE(in_corridor(corridor, {-10, 20}));
  corridor = extract_driving_corridor(t_intersection(5.4), Pose2d{0, 0, 0});
  EXPECT_TRUE(in_corridor(corridor, {10, 20}));
  EXPECT_TRUE(in_corridor(corridor, {-10, 20}));
  EXPECT_FALSE(in_corridor(corridor, {20, -8}));  // the closed south side is unaffected
}

TEST(DrivingCorridor, NoCurbsAndAllOccupied) {
  const auto open = extract_driving_corridor({}, Pose2d{1, 2, 3});
  EXPECT_EQ(cv::countNonZero(open.mask), 400 * 400);  // nothing bounds it: the whole grid
  // A curb in every cell: no free cell, an empty mask, contains() false everywhere.
  CorridorParams small;
  small.width_cells = small.height_cells = 10;
  std::vector<Eigen::Vector2d> everywhere;
  for (double x = -1.0; x < 1.0; x += 0.1)
    for (double y = -1.0; y < 1.0; y += 0.1) everywhere.push_back({x + 0.05, y + 0.05});
  const auto none = extract_driving_corridor(everywhere, Pose2d{}, small);
  EXPECT_TRUE(none.mask.empty());
  EXPECT_FALSE(none.contains({0, 0}));
}

// ---------------------------------------------------------------------------------------------------

struct Scene {
  Eigen::Vector3d normal;  // true unit normal, z up
  double offset = -1.9;    // plane height at x = y = 0 (LiDAR ~1.9 m above the road)
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> is_obstacle;
  std::vector<double> true_height;  // perpendicular height above the true plane
};

double plane_z(const Scene& s, double x, double y) {
  return s.offset - (s.normal.x() * x + s.normal.y() * y) / s.normal.z();
}

// Ground: a 60 x 10 m road, z noise sigma 2 cm. Obstacles: boxes (cars, a pedestrian) whose points lie
// 0.5..2 m above the plane.
Scene make_scene(unsigned seed, int n_ground, int n_obstacle_per_box) {
  Scene s;
  s.normal = (Eigen::AngleAxisd(1.0 * std::numbers::pi / 180, Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(2.0 * std::numbers::pi / 180, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ())
                 .normalized();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-30, 30), uy(-5, 5), uh(0.5, 2.0), u01(0, 1);
  std::normal_distribution<double> noise(0, 0.02);
  auto add = [&](double x, double y, double z, bool obstacle) {
    s.points.emplace_back(x, y, z);
    s.is_obstacle.push_back(obstacle);
    s.true_height.push_back((z - plane_z(s, x, y)) * s.normal.z());
  };
  for (int i = 0; i < n_ground; ++i) {
    const double x = ux(rng), y = uy(rng);
    add(x, y, plane_z(s, x, y) + noise(rng), false);
  }
  struct Box {
    double x, y, lx, ly;
  };
  for (const Box& b : {Box{8, 2, 4.5, 1.8}, Box{-15, -3, 4.5, 1.8}, Box{22, -1, 10, 2.5}, Box{-4, 3.5, 0.6, 0.6}}) {
    for (int i = 0; i < n_obstacle_per_box; ++i) {
      const double x = b.x + (u01(rng) - 0.5) * b.lx, y = b.y + (u01(rng) - 0.5) * b.ly;
      add(x, y, plane_z(s, x, y) + uh(rng) / s.normal.z(), true);
    }
  }
  return s;
}

double angle_deg(const Plane& p, const Eigen::Vector3d& truth) {
  const Eigen::Vector3d n = Eigen::Vector3d(-p.a0, -p.a1, 1).normalized();
  return std::acos(std::clamp(n.dot(truth), -1.0, 1.0)) * 180 / std::numbers::pi;
}

void check_scene(const Scene& s, const char* name) {
  const auto split = reject_obstacles(s.points, {});
  ASSERT_TRUE(split.plane_ok);
  const double err = angle_deg(split.plane, s.normal);
  EXPECT_LT(err, 0.5);
  EXPECT_NEAR(split.plane.a2, s.offset, 0.05);

  // Precision over everything labelled obstacle; recall over true obstacle points > 0.6 m up.
  std::size_t labelled = 0, labelled_true = 0, tall = 0, tall_found = 0;
  const auto is_labelled = [&](std::size_t i) { return height_above_plane(split.plane, s.points[i]) > 0.5; };
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const bool lab = is_labelled(i);
    labelled += lab;
    labelled_true += lab && s.is_obstacle[i];
    if (s.is_obstacle[i] && s.true_height[i] > 0.6) {
      ++tall;
      tall_found += lab;
    }
  }
  ASSERT_EQ(labelled, split.obstacles.size());
  ASSERT_EQ(split.ground.size() + split.obstacles.size(), s.points.size());
  const double precision = labelled ? double(labelled_true) / labelled : 0.0;
  const double recall = tall ? double(tall_found) / tall : 0.0;
  std::printf(
      "[ %s ] normal error %.4f deg, a2 %.4f (true %.2f), precision %.4f, recall %.4f (%zu obstacles of %zu points)\n",
      name, err, split.plane.a2, s.offset, precision, recall, split.obstacles.size(), s.points.size());
  EXPECT_GE(precision, 0.99);
  EXPECT_GE(recall, 0.95);
}

TEST(ObstacleRejection, RecoversTiltedPlaneAndLabelsObstacles) {
  // 4 x 200 obstacle points of 20800: under 1 - xi, so none enter the fit.
  check_scene(make_scene(42, 20000, 200), "4 % obstacles");
}

TEST(ObstacleRejection, ObstaclesAboveOneMinusXi) {
  // 4 x 500 of 22000 (9 %): more than 1 - xi, which Eq. 2 alone would let into the fit.
  check_scene(make_scene(7, 20000, 500), "9 % obstacles");
}

// A coach alongside (bus_occlusion, the paper's Fig. 12): its flank is a wall of returns from its skirt
// 0.3 m up to its roof, here 40 % of the corridor's points, far above 1 - xi. Eq. 2 on the lowest 95 %
// alone climbs the wall (19 deg in that scenario); the fit on the cells' lowest points must not.
TEST(ObstacleRejection, ACoachFlankDoesNotTiltTheGround) {
  Scene s = make_scene(3, 20000, 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> along(-6, 6), up(0.3, 3.2);
  for (int i = 0; i < 13000; ++i) {
    const double x = along(rng), y = -4.0, z = plane_z(s, x, y) + up(rng) / s.normal.z();
    s.points.emplace_back(x, y, z);
    s.is_obstacle.push_back(true);
    s.true_height.push_back((z - plane_z(s, x, y)) * s.normal.z());
  }
  check_scene(s, "40 % coach flank");
}

TEST(ObstacleRejection, FitIsExactOnNoiselessPlane) {
  std::vector<Eigen::Vector3d> pts;
  for (int i = -10; i <= 10; ++i)
    for (int j = -5; j <= 5; ++j) pts.emplace_back(i, j, 0.03 * i - 0.02 * j - 1.9);
  const auto plane = fit_ground_plane(pts, 1.0);
  ASSERT_TRUE(plane);
  EXPECT_NEAR(plane->a0, 0.03, 1e-12);
  EXPECT_NEAR(plane->a1, -0.02, 1e-12);
  EXPECT_NEAR(plane->a2, -1.9, 1e-12);
  // Eq. 3 on a flat plane is the height difference.
  EXPECT_NEAR(distance_to_plane(Plane{0, 0, -1.9}, {3, 4, -1.0}), 0.9, 1e-12);
  EXPECT_NEAR(distance_to_plane(Plane{0, 0, -1.9}, {3, 4, -2.5}), 0.6, 1e-12);
  EXPECT_NEAR(height_above_plane(Plane{0, 0, -1.9}, {3, 4, -2.5}), -0.6, 1e-12);
  // A 45 degree plane z = x: the point (0, 0, 1) is 1/sqrt(2) from it.
  EXPECT_NEAR(distance_to_plane(Plane{1, 0, 0}, {0, 0, 1}), std::sqrt(0.5), 1e-12);
}

TEST(ObstacleRejection, PointsBelowThePlaneAreGround) {
  std::vector<Eigen::Vector3d> pts;
  for (int i = -10; i <= 10; ++i)
    for (int j = -5; j <= 5; ++j) pts.emplace_back(i, j, -1.9);
  pts.emplace_back(1, 1, -3.0);  // a reflection 1.1 m under the road
  pts.emplace_back(2, 1, -1.0);  // 0.9 m above: an obstacle
  const auto split = reject_obstacles(pts, {});
  ASSERT_TRUE(split.plane_ok);
  ASSERT_EQ(split.obstacles.size(), 1u);
  EXPECT_EQ(split.obstacles[0], Eigen::Vector3d(2, 1, -1.0));
  EXPECT_EQ(split.ground.size(), pts.size() - 1);
}

TEST(ObstacleRejection, EdgeCases) {
  // Empty: no plane, nothing out.
  auto split = reject_obstacles({}, {});
  EXPECT_FALSE(split.plane_ok);
  EXPECT_TRUE(split.ground.empty());
  EXPECT_TRUE(split.obstacles.empty());
  // Two points: no plane; kept as ground (nothing is rejected without a plane).
  split = reject_obstacles({{0, 0, 0}, {1, 0, 5}}, {});
  EXPECT_FALSE(split.plane_ok);
  EXPECT_EQ(split.ground.size(), 2u);
  EXPECT_TRUE(split.obstacles.empty());
  EXPECT_FALSE(fit_ground_plane({{0, 0, 0}, {1, 0, 5}}, 0.95));
  // Collinear in x-y (one scan line): degenerate.
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(i, 2 * i, -1.9);
  EXPECT_FALSE(fit_ground_plane(line, 0.95));
  EXPECT_FALSE(reject_obstacles(line, {}).plane_ok);
  // Bad fraction.
  EXPECT_FALSE(fit_ground_plane({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 0.0));
  EXPECT_FALSE(fit_ground_plane({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, std::numeric_limits<double>::quiet_NaN()));
  // Non-finite points are dropped before anything else.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> pts;
  for (int i = -5; i <= 5; ++i)
    for (int j = -5; j <= 5; ++j) pts.emplace_back(i, j, -1.9);
  pts.emplace_back(nan, 0, 0);
  pts.emplace_back(0, inf, 0);
  pts.emplace_back(0, 0, -inf);
  pts.emplace_back(1, 1, 0.0);  // obstacle
  split = reject_obstacles(pts, {});
  ASSERT_TRUE(split.plane_ok);
  EXPECT_NEAR(split.plane.a2, -1.9, 0.02);
  EXPECT_EQ(split.ground.size() + split.obstacles.size(), pts.size() - 3);
  EXPECT_EQ(split.obstacles.size(), 1u);
  for (const auto& p : split.ground) EXPECT_TRUE(p.allFinite());
  // Only NaNs: nothing left.
  split = reject_obstacles({{nan, nan, nan}, {nan, 0, 0}, {0, 0, nan}}, {});
  EXPECT_FALSE(split.plane_ok);
  EXPECT_TRUE(split.ground.empty());
}

}  // namespace
}  // namespace lidarloop
