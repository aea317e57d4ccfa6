// The curb occlusion measurement on a straight road: what it counts as hidden, visible or left out is
// checked against which boxes each sample's ray crosses, worked out from the geometry alone.
#include <gtest/gtest.h>

#include "sim/curb_visibility.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// A straight two-way road along x, 7 m curb to curb (curbs at y = +-3.5), flat and smooth.
const std::string kStraightRoad = R"(name: straight
origin: {lat: 31.0, lon: 121.0}
geometry: {roughness_class: none, sidewalk_cross_slope: 0}
road_defaults: {cross_slope: 0}
roads:
  - {name: main, points: [[0, 0], [200, 0]], width: 7.0}
)";
constexpr double kRightCurbY = -3.5;
constexpr double kSensorHeight = 1.9;  // the HDL-32E's mount height (sim/hdl32e.hpp)
const Eigen::Vector2d kSensorXY(100, 1.0);

// An upright box (a coach's body or a wall) standing through the ground, taller than the sensor: a ray
// to a curb crosses it exactly where its plan view crosses the footprint.
struct Box {
  Eigen::Vector2d centre, half;
  static constexpr float kBottom = -1, kTop = 4;
  // Slab test in plan view on the segment a -> b.
  bool crossed_by(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
    double t0 = 0, t1 = 1;
    for (int k = 0; k < 2; ++k) {
      const double lo = centre[k] - half[k], hi = centre[k] + half[k], d = b[k] - a[k];
      if (std::abs(d) < 1e-12) {
        if (a[k] < lo || a[k] > hi) return false;
        continue;
      }
      double ta = (lo - a[k]) / d, tb = (hi - a[k]) / d;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
  void add_to(TriangleMesh& mesh, const Eigen::Vector2d& at) const {
    add_box(mesh, at.cast<float>(), half.cast<float>(), 0, kBottom, kTop, test::materials().id("building", "test"));
  }
};

// A coach-sized box (12 m x 2.3 m) in the right lane, 0.2 m from the right curb, between the sensor
// and that curb.
const Box kCoach{{100, kRightCurbY + 0.2 + 1.15}, {6, 1.15}};

struct Road {
  World world = test::world_from_yaml(kStraightRoad);
  std::vector<Eigen::Vector3f> samples = curb_top_samples(world, CurbVisibilityConfig{}.spacing_m);
  Eigen::Vector3f sensor() const {
    return {float(kSensorXY.x()), float(kSensorXY.y()), float(world.pavement()(kSensorXY) + kSensorHeight)};
  }
  bool in_range(const Eigen::Vector3f& s) const {
    const double d = (s.head<2>().cast<double>() - kSensorXY).norm();
    const CurbVisibilityConfig c;
    return d >= c.min_range_m && d <= c.max_range_m;
  }
  std::vector<Eigen::Vector3f> right_curb() const {
    std::vector<Eigen::Vector3f> out;
    for (const auto& s : samples)
      if (std::abs(s.y() - kRightCurbY) < 0.01) out.push_back(s);
    return out;
  }
};

void add_actor_box(RayScene& scene, const Box& box) {
  TriangleMesh mesh;
  box.add_to(mesh, Eigen::Vector2d::Zero());
  scene.add_actor(scene.add_prototype(mesh),
                  Eigen::Isometry3d(Eigen::Translation3d(box.centre.x(), box.centre.y(), 0)));
  scene.commit();
}

TEST(CurbVisibility, SamplesLieOnTheCurbTopsAtTheSpacing) {
  const Road road;
  const Eigen::Vector3f a = road.right_curb()[0], b = road.right_curb()[1];
  EXPECT_NEAR((a - b).head<2>().norm(), CurbVisibilityConfig{}.spacing_m, 1e-4);
  // The world's default curb: 0.15 m above the pavement beside it.
  const Eigen::Vector2d foot = a.head<2>().cast<double>();
  EXPECT_NEAR(a.z() - road.world.pavement()(foot), 0.15, 0.005);
  // Both curbs of the 200 m road, and its ends: about its perimeter over the spacing.
  EXPECT_NEAR(double(road.samples.size()), 2 * (200 + 7) / 0.25, 10);
}

TEST(CurbVisibility, WithoutActorsNothingIsHidden) {
  const Road road;
  const RayScene scene(road.world.mesh);
  const CurbVisibility v = curb_visibility(scene, road.samples, road.sensor(), 0, {});
  int in_range = 0;
  for (const auto& s : road.samples) in_range += road.in_range(s);
  ASSERT_GT(in_range, 300);  // both curbs, ~2 x 49 m of each within 25 m
  EXPECT_EQ(v.hidden, 0);
  // On an open straight road every curb top in range is in sight: the curb's own corner is not in
  // the way of a ray aimed at it.
  EXPECT_EQ(v.visible, in_range);
  EXPECT_EQ(v.blocked_by_world, 0);
}

TEST(CurbVisibility, ACoachBesideTheCarHidesTheCurbBehindIt) {
  const Road road;
  RayScene scene(road.world.mesh);
  add_actor_box(scene, kCoach);
  const Eigen::Vector3f sensor = road.sensor();
  int expected_hidden = 0, in_range = 0;
  for (const auto& s : road.samples) {
    if (!road.in_range(s)) continue;
    ++in_range;
    expected_hidden += kCoach.crossed_by(kSensorXY, s.head<2>().cast<double>());
  }
  // The near face (2 m from the sensor, the curb 4.5 m) subtends +-6 m * 4.5 / 2 = +-13.5 m of curb.
  ASSERT_NEAR(expected_hidden, 27 / 0.25, 2);
  const CurbVisibility v = curb_visibility(scene, road.samples, sensor, 0, {});
  EXPECT_NEAR(v.hidden, expected_hidden, 2);
  EXPECT_EQ(v.hidden + v.visible, in_range);
  EXPECT_EQ(v.blocked_by_world, 0);
}

TEST(CurbVisibility, AnActorOnTheFarSideHidesNothingOfThisCurb) {
  const Road road;
  RayScene scene(road.world.mesh);
  // A car-sized box in the left lane, beside the car on the side away from the right curb.
  add_actor_box(scene, {{kSensorXY.x(), 2.3}, {2.3, 0.9}});
  const std::vector<Eigen::Vector3f> right = road.right_curb();
  int in_range = 0;
  for (const auto& s : right) in_range += road.in_range(s);
  ASSERT_GT(in_range, 150);
  const CurbVisibility v = curb_visibility(scene, right, road.sensor(), 0, {});
  EXPECT_EQ(v.hidden, 0);
  EXPECT_EQ(v.visible, in_range);
  // And it does hide the left curb behind it, which is what the samples are there for.
  EXPECT_GT(curb_visibility(scene, road.samples, road.sensor(), 0, {}).hidden, 50);
}

TEST(CurbVisibility, WhatTheStaticWorldHidesIsLeftOutNotCountedAsHidden) {
  // A wall (part of the static world) between the car and the curb, partly behind the coach as seen
  // from the sensor and partly beyond it: a sample behind the wall is left out whether or not the
  // coach is in the way too; only the samples behind the coach alone are hidden.
  const Road road;
  const Box wall{{112, -2.85}, {2, 0.15}};
  TriangleMesh mesh = road.world.mesh;
  wall.add_to(mesh, wall.centre);
  RayScene scene(mesh);
  add_actor_box(scene, kCoach);
  int expected_hidden = 0, expected_left_out = 0, in_range = 0, behind_both = 0;
  for (const auto& s : road.samples) {
    if (!road.in_range(s)) continue;
    ++in_range;
    const Eigen::Vector2d p = s.head<2>().cast<double>();
    const bool by_wall = wall.crossed_by(kSensorXY, p), by_coach = kCoach.crossed_by(kSensorXY, p);
    expected_left_out += by_wall;
    expected_hidden += by_coach && !by_wall;
    behind_both += by_coach && by_wall;
  }
  ASSERT_GT(behind_both, 4);                      // the case the exact check is for
  ASSERT_GT(expected_left_out - behind_both, 4);  // and the wall alone
  const CurbVisibility v = curb_visibility(scene, road.samples, road.sensor(), 0, {});
  EXPECT_NEAR(v.blocked_by_world, expected_left_out, 2);
  EXPECT_NEAR(v.hidden, expected_hidden, 2);
  EXPECT_EQ(v.hidden + v.visible + v.blocked_by_world, in_range);
}

TEST(CurbVisibility, OnlyTheLocalizersRangeCounts) {
  const Road road;
  const RayScene scene(road.world.mesh);
  CurbVisibilityConfig narrow;
  narrow.max_range_m = 10;
  const CurbVisibility v = curb_visibility(scene, road.right_curb(), road.sensor(), 0, narrow);
  // The right curb, 4.5 m to the side: +-sqrt(10^2 - 4.5^2) = +-8.93 m of it.
  EXPECT_NEAR(v.visible, 2 * 8.93 / 0.25, 2);
}

}  // namespace
}  // namespace lidarloop
