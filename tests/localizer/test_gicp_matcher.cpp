// The gicp method's matcher on a synthetic street whose truth is known exactly: ground, two building
// fronts, poles and boxes (parked cars) as the map; the same street sampled from a car at a known pose
// as the scan. Open3D's GICP must find that pose from a prior off by a known (dx, dy, dyaw), give the
// same bits twice (whatever the caller's OpenMP thread count), and refuse bad input with a status.
#include <omp.h>

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "localizer/gicp_matcher.hpp"

namespace lidarloop {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Points on the street's surfaces, `spacing` apart, each jittered by up to `jitter` along the
// surface (so map and scan sample the surfaces at different places, as a real scan does).
std::vector<Eigen::Vector3d> street(double spacing, double jitter, uint64_t seed, bool with_cross_structure = true) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> j(-jitter, jitter);
  std::vector<Eigen::Vector3d> out;
  for (double x = -50; x <= 50; x += spacing)
    for (double y = -9; y <= 9; y += spacing) out.emplace_back(x + j(rng), y + j(rng), 0.0);  // ground
  for (double x = -50; x <= 50; x += spacing)
    for (double z = 0; z <= 6; z += spacing) {
      out.emplace_back(x + j(rng), 9.0, z + j(rng));  // building fronts
      out.emplace_back(x + j(rng), -9.0, z + j(rng));
    }
  if (!with_cross_structure) return out;
  for (double y = -9; y <= 9; y += spacing)  // the building across the end of the street
    for (double z = 0; z <= 6; z += spacing) out.emplace_back(30.0, y + j(rng), z + j(rng));
  for (double px = -45; px <= 45; px += 15)  // poles: 0.2 m across, 5 m high, on both sidewalks
    for (double side : {-7.0, 7.0})
      for (double z = 0; z <= 5; z += spacing)
        for (int k = 0; k < 8; ++k) {
          const double a = 2 * kPi * k / 8 + j(rng);
          out.emplace_back(px + 0.1 * std::cos(a), side + 0.1 * std::sin(a), z + j(rng));
        }
  for (double bx : {-30.0, -5.0, 22.0})  // parked cars: 4.5 x 1.8 x 1.5 m boxes
    for (double z = 0; z <= 1.5; z += spacing) {
      for (double a = 0; a <= 4.5; a += spacing) {  // the long sides
        out.emplace_back(bx + a + j(rng), 5.0, z + j(rng));
        out.emplace_back(bx + a + j(rng), 6.8, z + j(rng));
      }
      for (double a = 0; a <= 1.8; a += spacing) {  // the ends: faces across the road, which pin x
        out.emplace_back(bx, 5.0 + a + j(rng), z + j(rng));
        out.emplace_back(bx + 4.5, 5.0 + a + j(rng), z + j(rng));
      }
    }
  return out;
}

Eigen::Isometry3d pose(double x, double y, double yaw_deg) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw_deg * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, 0);
  return t;
}

// The street as the car at `truth` sees it: its own sampling, in the vehicle frame.
std::vector<Eigen::Vector3d> scan_from(const Eigen::Isometry3d& truth, bool with_cross_structure = true) {
  std::vector<Eigen::Vector3d> scan;
  for (const Eigen::Vector3d& p : street(0.15, 0.05, 11, with_cross_structure)) scan.push_back(truth.inverse() * p);
  return scan;
}

GicpTarget target_of(const std::vector<Eigen::Vector3d>& map, const GicpParams& p) {
  GicpTarget t;
  t.build(map, Eigen::Vector2d::Zero(), p);
  return t;
}

double yaw_of(const Eigen::Isometry3d& t) { return std::atan2(t.linear()(1, 0), t.linear()(0, 0)); }

GicpParams test_params() {
  GicpParams p;
  p.scan_voxel_m = 0.5;  // the street is small: keep enough scan points
  return p;
}

TEST(GicpMatcher, RecoversAKnownOffset) {
  const GicpParams p = test_params();
  const GicpTarget target = target_of(street(0.2, 0.05, 7), p);
  const Eigen::Isometry3d truth = pose(3.0, 1.0, 4.0);
  const Eigen::Isometry3d prior = pose(3.0 + 0.3, 1.0 - 0.2, 4.0 + 1.5);  // off by (0.3 m, -0.2 m, 1.5 deg)
  const GicpResult r = gicp_match(scan_from(truth), prior, target, p, 1.0);
  ASSERT_TRUE(r.ok()) << gicp_status_name(r.status);
  EXPECT_NEAR(r.pose.translation().x(), 3.0, 0.005);
  EXPECT_NEAR(r.pose.translation().y(), 1.0, 0.005);
  EXPECT_NEAR(yaw_of(r.pose) * 180 / kPi, 4.0, 0.05);
  EXPECT_GT(r.fitness, 0.9);
  // The covariance is a covariance: symmetric, positive definite, and at least the map's own error.
  EXPECT_TRUE(r.covariance.isApprox(r.covariance.transpose()));
  EXPECT_GT(r.covariance.llt().matrixL().toDenseMatrix().diagonal().minCoeff(), 0.0);
  EXPECT_GE(r.covariance(0, 0), p.map_sigma_m * p.map_sigma_m);
}

TEST(GicpMatcher, ACorridorWithoutCrossStructureIsUncertainAlongIt) {
  // Ground and two parallel walls: nothing says where along x the car is. The covariance must say so
  // (its x variance far above its y variance), whatever x the registration ended at.
  GicpParams p = test_params();
  p.map_sigma_m = p.map_sigma_yaw_rad = 0;  // the match's own covariance alone
  const GicpTarget target = target_of(street(0.2, 0.05, 7, false), p);
  const Eigen::Isometry3d truth = pose(0.0, 1.0, 0.0);
  const GicpResult r = gicp_match(scan_from(truth, false), pose(0.2, 0.8, 0.5), target, p, 1.0);
  ASSERT_NE(r.status, GicpStatus::few_scan_points);
  EXPECT_NEAR(r.pose.translation().y(), 1.0, 0.01);
  if (r.ok()) {
    EXPECT_GT(r.covariance(0, 0), 100 * r.covariance(1, 1));
  }
}

TEST(GicpMatcher, TwoRunsGiveTheSameBitsAtAnyOpenMpThreadCount) {
  const GicpParams p = test_params();
  const std::vector<Eigen::Vector3d> map = street(0.2, 0.05, 7), scan = scan_from(pose(3.0, 1.0, 4.0));
  const Eigen::Isometry3d prior = pose(3.3, 0.8, 5.5);
  auto run = [&](int threads) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);  // what a caller may have set: the matcher must not depend on it
    const GicpTarget target = target_of(map, p);
    const GicpResult r = gicp_match(scan, prior, target, p, 1.0);
    EXPECT_EQ(omp_get_max_threads(), threads) << "the matcher must restore the caller's setting";
    omp_set_num_threads(saved);
    return r;
  };
  const GicpResult a = run(1), b = run(1), c = run(4);
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a.pose.matrix() == b.pose.matrix());
  EXPECT_TRUE(a.covariance == b.covariance);
  EXPECT_TRUE(a.pose.matrix() == c.pose.matrix()) << "4 OpenMP threads changed the result";
  EXPECT_TRUE(a.covariance == c.covariance);
  EXPECT_EQ(a.fitness, c.fitness);
}

TEST(GicpMatcher, BadInputGivesAStatusNotACrash) {
  const GicpParams p = test_params();
  const GicpTarget target = target_of(street(0.2, 0.05, 7), p);
  const Eigen::Isometry3d prior = pose(3.0, 1.0, 4.0);
  EXPECT_EQ(gicp_match({}, prior, target, p, 1.0).status, GicpStatus::few_scan_points);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector3d> all_nan(5000, Eigen::Vector3d(nan, 0, nan));
  EXPECT_EQ(gicp_match(all_nan, prior, target, p, 1.0).status, GicpStatus::few_scan_points);
  // NaN among good points: dropped, the match still works.
  std::vector<Eigen::Vector3d> mixed = scan_from(prior);
  for (size_t i = 0; i < mixed.size(); i += 10)
    mixed[i] = Eigen::Vector3d(nan, 1, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(gicp_match(mixed, prior, target, p, 1.0).ok());
  // No map (an empty target, or one of NaN): no match.
  EXPECT_EQ(gicp_match(scan_from(prior), prior, GicpTarget(), p, 1.0).status, GicpStatus::few_map_points);
  EXPECT_EQ(gicp_match(scan_from(prior), prior, target_of(all_nan, p), p, 1.0).status, GicpStatus::few_map_points);
  // A scan of somewhere else entirely (nothing within reach of the map): not a match.
  std::vector<Eigen::Vector3d> elsewhere = scan_from(prior);
  for (Eigen::Vector3d& q : elsewhere) q.z() += 30;  // a street of floating surfaces
  EXPECT_FALSE(gicp_match(elsewhere, prior, target, p, 1.0).ok());
}

TEST(GicpMatcher, ATargetCutAnewKeepsCovariancesThatAreTheSameAsFresh) {
  // A target built after another one nearby keeps the covariances the two share; they must be exactly
  // the ones a fresh build computes (same map points, same neighbours), so the match is the same.
  const GicpParams p = test_params();
  const std::vector<Eigen::Vector3d> map = street(0.2, 0.05, 7), scan = scan_from(pose(3.0, 1.0, 4.0));
  GicpTarget fresh, reused;
  fresh.build(map, {5, 0}, p);
  reused.build(map, {0, 0}, p);
  reused.build(map, {5, 0}, p);
  const GicpResult a = gicp_match(scan, pose(3.3, 0.8, 5.5), fresh, p, 1.0);
  const GicpResult b = gicp_match(scan, pose(3.3, 0.8, 5.5), reused, p, 1.0);
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a.pose.matrix() == b.pose.matrix());
  EXPECT_TRUE(a.covariance == b.covariance);
}

TEST(GicpMatcher, TheTargetIsReusedNearWhereItWasCut) {
  const GicpParams p = test_params();
  GicpTarget target = target_of(street(0.5, 0.0, 1), p);
  EXPECT_TRUE(target.covers({p.target_reuse_m * 0.9, 0}, p));
  EXPECT_FALSE(target.covers({p.target_reuse_m * 1.1, 0}, p));
  EXPECT_FALSE(GicpTarget().covers({0, 0}, p));
  EXPECT_GE(GicpTarget::radius(p), p.max_range_m + p.target_reuse_m);
}

}  // namespace
}  // namespace lidarloop
