// The curb match's covariance (point-to-line information) and its Gauss-Newton finish, on synthetic
// curbs with known truth: a 45 m bend (the campus's south-east curve) that runs into a straight.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "common/units.hpp"
#include "localizer/curb_match_covariance.hpp"
#include "localizer/map_index.hpp"

namespace lidarloop {
namespace {

constexpr double kSpacing = 0.1;  // m between map curb points, as the curb layer densifies them
constexpr double kRadius = 45.0;  // m, the road's centre line in the bend
constexpr double kHalfWidth = 4.0;

struct CurbMap {
  std::vector<Eigen::Vector2d> points, tangents;
};

// Two curbs kHalfWidth either side of a road that turns left about the origin from angle -pi/2 to 0
// (radius kRadius) and then runs straight up +y from (kRadius, 0).
CurbMap bend_into_straight() {
  CurbMap m;
  for (double side : {-kHalfWidth, kHalfWidth}) {
    const double r = kRadius + side;
    const int steps = int(std::ceil(r * std::numbers::pi / 2 / kSpacing));
    for (int k = 0; k < steps; ++k) {
      const double a = -std::numbers::pi / 2 + std::numbers::pi / 2 * double(k) / steps;
      m.points.push_back(r * Eigen::Vector2d(std::cos(a), std::sin(a)));
      m.tangents.push_back(Eigen::Vector2d(-std::sin(a), std::cos(a)));
    }
    for (double y = 0; y <= 60; y += kSpacing) {
      m.points.push_back({r, y});
      m.tangents.push_back({0, 1});
    }
  }
  return m;
}

// The car on the road's centre line at angle `a` of the bend, heading along it.
Pose2d on_bend(double a) {
  return {kRadius * std::cos(a), kRadius * std::sin(a), wrap_angle(a + std::numbers::pi / 2)};
}

// The map's curbs within `range` of the car, in its vehicle frame: what a perfect detector sees.
std::vector<Eigen::Vector2d> seen_from(const Pose2d& truth, const CurbMap& map, double range) {
  const Pose2d to_vehicle = truth.inverse();
  std::vector<Eigen::Vector2d> seen;
  for (const Eigen::Vector2d& p : map.points)
    if ((p - Eigen::Vector2d(truth.x, truth.y)).norm() < range) seen.push_back(to_vehicle.apply(p));
  return seen;
}

// `pose` turned by `angle` about the bend's centre: the direction a circle's curbs cannot see.
Pose2d turned_about_centre(const Pose2d& pose, double angle) {
  const Eigen::Vector2d p = Eigen::Rotation2Dd(angle) * Eigen::Vector2d(pose.x, pose.y);
  return {p.x(), p.y(), wrap_angle(pose.yaw + angle)};
}

double position_error(const Pose2d& a, const Pose2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

TEST(CurbMatchCovariance, ABendLeavesItsTurnAboutTheCentreFree) {
  const CurbMap map = bend_into_straight();
  const MapIndex index(map.points);
  const Pose2d truth = on_bend(-std::numbers::pi / 4);  // mid-bend: only arcs within 20 m
  const CurbMatchQuality q = curb_match_quality(seen_from(truth, map, 20.0), truth, index, map.tangents, {});
  // Across the road the curbs fix the car to the floor; along it (with the heading that goes with it)
  // hardly: the circle turned about its centre is the same circle.
  const Eigen::Vector2d forward(std::cos(truth.yaw), std::sin(truth.yaw)), left(-forward.y(), forward.x());
  const Eigen::Matrix2d C = q.covariance.topLeftCorner<2, 2>();
  EXPECT_LT(std::sqrt(left.dot(C * left)), 0.02);
  EXPECT_GT(std::sqrt(forward.dot(C * forward)), 10.0);
  EXPECT_EQ(q.inliers, seen_from(truth, map, 20.0).size());
}

TEST(CurbMatchCovariance, FinishRecoversAKnownOffsetWhereTheBendMeetsTheStraight) {
  const CurbMap map = bend_into_straight();
  const MapIndex index(map.points);
  const Pose2d truth = on_bend(-5 * kDeg);  // 4 m before the straight: both in view
  const std::vector<Eigen::Vector2d> seen = seen_from(truth, map, 20.0);
  // Off along the bend's weak direction (0.4 m along, 0.5 deg) and 5 cm across, as ICP leaves it.
  Pose2d start = turned_about_centre(truth, 0.4 / kRadius);
  start.x += 0.05;
  const Pose2d refined = finish_curb_match(seen, start, index, map.tangents, {}).pose;
  EXPECT_LT(position_error(refined, truth), 0.005);
  EXPECT_LT(std::abs(wrap_angle(refined.yaw - truth.yaw)), 0.01 * kDeg);
  // And the covariance there pins the position along the road too.
  const CurbMatchQuality q = curb_match_quality(seen, refined, index, map.tangents, {});
  const Eigen::Vector2d forward(std::cos(truth.yaw), std::sin(truth.yaw));
  EXPECT_LT(std::sqrt(forward.dot(q.covariance.topLeftCorner<2, 2>() * forward)), 0.05);
}

TEST(CurbMatchCovariance, FinishLeavesAPoseTheCurbsCannotPlaceAlongTheRoad) {
  // Mid-bend the arcs leave the turn about their centre free; on a straight, the position along it.
  // ICP has converged on what they do fix; a finish would only follow their noise along the rest.
  const CurbMap map = bend_into_straight();
  const MapIndex index(map.points);
  const Pose2d truth = on_bend(-std::numbers::pi / 4);
  Pose2d start = turned_about_centre(truth, 0.4 / kRadius);
  start.x += 0.05;
  Pose2d refined = finish_curb_match(seen_from(truth, map, 20.0), start, index, map.tangents, {}).pose;
  EXPECT_EQ(refined.x, start.x);
  EXPECT_EQ(refined.yaw, start.yaw);
  const Pose2d on_straight{kRadius, 40.0, std::numbers::pi / 2};
  start = {kRadius + 0.05, 40.5, on_straight.yaw};
  refined = finish_curb_match(seen_from(on_straight, map, 15.0), start, index, map.tangents, {}).pose;
  EXPECT_EQ(refined.y, start.y);
}

TEST(CurbMatchCovariance, FinishLeavesThePoseWithoutInliersOrIterations) {
  const CurbMap map = bend_into_straight();
  const MapIndex index(map.points);
  const Pose2d truth = on_bend(-5 * kDeg);
  Pose2d start = truth;
  start.x += 2.5;  // across the road: the features land 1.5 m and 6.5 m from the curbs
  const Pose2d refined = finish_curb_match(seen_from(truth, map, 20.0), start, index, map.tangents, {}).pose;
  EXPECT_EQ(refined.x, start.x);
  EXPECT_EQ(refined.y, start.y);
  CurbMatchNoise none;
  none.refine_iterations = 0;
  const Pose2d unchanged = finish_curb_match(seen_from(truth, map, 20.0), start, index, map.tangents, none).pose;
  EXPECT_EQ(unchanged.x, start.x);
  EXPECT_EQ(unchanged.yaw, start.yaw);
}

}  // namespace
}  // namespace lidarloop
