// Curb map matching (paper section 3.1, Eq. 9-13; M-ICP Eq. 21-22) on synthetic curbs with known truth.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "common/units.hpp"
#include "localizer/probabilistic_icp.hpp"

namespace lidarloop {
namespace {

constexpr double kSpacing = 0.1;  // m between map curb points, as the curb layer densifies them

void add_segment(std::vector<Eigen::Vector2d>& out, Eigen::Vector2d a, Eigen::Vector2d b) {
  const int steps = int(std::ceil((b - a).norm() / kSpacing));
  for (int k = 0; k <= steps; ++k) out.push_back(a + (b - a) * (double(k) / steps));
}

void add_arc(std::vector<Eigen::Vector2d>& out, Eigen::Vector2d centre, double radius, double from, double to) {
  const int steps = int(std::ceil(std::abs(to - from) * radius / kSpacing));
  for (int k = 0; k <= steps; ++k) {
    const double a = from + (to - from) * (double(k) / steps);
    out.push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
}

// A road 10 m wide along x (curbs y = 0 and y = 10) with a street 10 m wide leaving it to +y at x = 0,
// its two block corners rounded with 5 m radius: gives both directions and rotation something to hold.
std::vector<Eigen::Vector2d> road_map() {
  std::vector<Eigen::Vector2d> m;
  add_segment(m, {-30, 0}, {30, 0});
  add_segment(m, {-30, 10}, {-10, 10});
  add_segment(m, {10, 10}, {30, 10});
  add_arc(m, {-10, 15}, 5, -std::numbers::pi / 2, 0);                 // (-10, 10) -> (-5, 15)
  add_arc(m, {10, 15}, 5, std::numbers::pi, 1.5 * std::numbers::pi);  // (5, 15) -> (10, 10)
  add_segment(m, {-5, 15}, {-5, 35});
  add_segment(m, {5, 15}, {5, 35});
  return m;
}

const Pose2d kTruth{0.8, -0.5, 3 * kDeg};  // the pose error ICP must find: truth.apply(curb) = map
constexpr double kNoise = 0.02;            // m, curb detection noise
constexpr size_t kInliers = 300;

// Detected curbs: kInliers map points seen through the pose error, with noise. With `outliers`, 30 % of
// the result are fake curbs in the world frame: the flank of a 12 m row of parked vans against the bottom
// curb (2.0 m wide, so their sides are 2.0 m out: inside the default 2 m correspondence gate, outside
// d_g = 1 m) and scattered returns on the road.
std::vector<Eigen::Vector2d> detected_curbs(const std::vector<Eigen::Vector2d>& map, bool outliers, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoise);
  std::uniform_int_distribution<size_t> pick(0, map.size() - 1);
  const Pose2d to_vehicle = kTruth.inverse();
  auto observe = [&](const Eigen::Vector2d& world) {
    return Eigen::Vector2d(to_vehicle.apply(world) + Eigen::Vector2d(noise(rng), noise(rng)));
  };
  std::vector<Eigen::Vector2d> curbs;
  for (size_t i = 0; i < kInliers; ++i) curbs.push_back(observe(map[pick(rng)]));
  if (outliers) {
    constexpr int kParked = 100;           // one every 0.12 m
    constexpr double kParkedOffset = 2.0;  // m from the bottom curb
    for (int k = 0; k < kParked; ++k) curbs.push_back(observe({-4.0 + 12.0 * k / kParked, kParkedOffset}));
    constexpr int kScattered = 29;  // pedestrians, bins, vegetation on the road surface
    std::uniform_real_distribution<double> along(-25, 25), across(3, 7);
    for (int k = 0; k < kScattered; ++k) curbs.push_back(observe({along(rng), across(rng)}));
  }
  return curbs;
}

double translation_error(const Pose2d& t) { return std::hypot(t.x - kTruth.x, t.y - kTruth.y); }
double heading_error_deg(const Pose2d& t) { return std::abs(wrap_angle(t.yaw - kTruth.yaw)) / kDeg; }

TEST(IcpMapIndex, NearestPointAndDistance) {
  const MapIndex index({{0, 0}, {1, 0}, {5, 5}});
  const auto [i, d] = index.nearest({1.3, 0.4});
  EXPECT_EQ(i, 1u);
  EXPECT_NEAR(d, 0.5, 1e-12);
  MapIndex moved = MapIndex({{2, 2}});  // the tree must follow its points through a move
  EXPECT_NEAR(moved.nearest({2, 3}).second, 1.0, 1e-12);
  EXPECT_TRUE(std::isinf(MapIndex({}).nearest({0, 0}).second));
}

// The buckets must give the KD-tree's answer whenever it lies within the gate, and nothing otherwise,
// for gates up to a bucket (one block of buckets), up to four (rings of them) and beyond (tree), inside
// the map and far off it.
TEST(IcpMapIndex, NearestWithinAgreesWithTheTree) {
  const std::vector<Eigen::Vector2d> map = road_map();
  const MapIndex index(map);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-45, 45);
  size_t found = 0;
  for (double gate : {0.05, 0.3, 1.0, 1.7, 2.5}) {
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector2d q(u(rng), u(rng));
      const auto [ti, td] = index.nearest(q);
      const auto [bi, bd] = index.nearest_within(q, gate);
      if (td <= gate) {
        ASSERT_NEAR(bd, td, 1e-12) << "query " << q.transpose() << " gate " << gate;
        ++found;
      } else {
        ASSERT_EQ(bi, SIZE_MAX) << "query " << q.transpose() << " gate " << gate;
        ASSERT_TRUE(std::isinf(bd));
      }
    }
  }
  EXPECT_GT(found, 200u);  // the queries did land near curbs often enough to test something
  // An index without a tree answers gates up to four buckets from its rings, and refuses wider ones.
  const MapIndex rings_only(map, 0.5, MapIndex::Queries::within_only);
  const Eigen::Vector2d near_curb = map[map.size() / 2] + Eigen::Vector2d(1.3, 1.3);
  EXPECT_NEAR(rings_only.nearest_within(near_curb, 2.0).second, index.nearest(near_curb).second, 1e-12);
  EXPECT_THROW(rings_only.nearest_within(near_curb, 2.5), std::logic_error);
  // A point exactly on the gate counts; NaN and far-away queries find nothing, without a crash.
  EXPECT_EQ(MapIndex({{0, 0}, {3, 0}}).nearest_within({0.0, 0.5}, 0.5).first, 0u);
  EXPECT_EQ(index.nearest_within({std::nan(""), 0.0}, 1.0).first, SIZE_MAX);
  EXPECT_EQ(index.nearest_within({1e300, -1e300}, 1.0).first, SIZE_MAX);
  EXPECT_EQ(MapIndex({}).nearest_within({0, 0}, 1.0).first, SIZE_MAX);
  // Two points 10 km apart: the buckets grow rather than allocate 10^8 of them, and still find both.
  const MapIndex sparse({{0, 0}, {1e4, 1e4}});
  EXPECT_EQ(sparse.nearest_within({0.3, 0.0}, 0.5).first, 0u);
  EXPECT_EQ(sparse.nearest_within({1e4, 1e4 + 0.2}, 0.5).first, 1u);
}

TEST(IcpFitRigid, RecoversKnownTransformExactly) {
  const Pose2d truth{-1.7, 0.4, 2.5};  // a large rotation: no small-angle shortcut
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-20, 20);
  std::vector<Eigen::Vector2d> src, dst;
  for (int i = 0; i < 50; ++i) {
    src.emplace_back(u(rng), u(rng));
    dst.push_back(truth.apply(src.back()));
  }
  Pose2d t = fit_rigid_2d(src, dst);
  EXPECT_NEAR(t.x, truth.x, 1e-9);
  EXPECT_NEAR(t.y, truth.y, 1e-9);
  EXPECT_NEAR(t.yaw, truth.yaw, 1e-12);

  // A wild pair with weight zero must not change anything; with weight one it must.
  src.emplace_back(0, 0);
  dst.emplace_back(100, 100);
  std::vector<double> w(src.size(), 1.0);
  w.back() = 0.0;
  t = fit_rigid_2d(src, dst, &w);
  EXPECT_NEAR(t.x, truth.x, 1e-9);
  EXPECT_NEAR(t.yaw, truth.yaw, 1e-12);
  EXPECT_GT(std::abs(fit_rigid_2d(src, dst).x - truth.x), 0.1);
}

TEST(Icp, RecoversOffsetOnCleanCurbs) {
  const auto map = road_map();
  const MapIndex index(map);
  const IcpResult r = icp(index, detected_curbs(map, false, 1), {}, IcpParams{});
  EXPECT_LT(translation_error(r.t), 0.02);
  EXPECT_LT(heading_error_deg(r.t), 0.1);
  EXPECT_LT(r.rmse, 2 * kNoise);
  EXPECT_EQ(r.outlier_ratio, 0.0);
}

TEST(Icp, MIcpRecoversOffsetOnCleanCurbs) {
  const auto map = road_map();
  const MapIndex index(map);
  const IcpResult r = m_icp(index, detected_curbs(map, false, 1), {}, MIcpParams{});
  EXPECT_LT(translation_error(r.t), 0.02);
  EXPECT_LT(heading_error_deg(r.t), 0.1);
}

TEST(ProbabilisticIcp, RecoversOffsetDespiteParkedVansWherePlainIcpFails) {
  const auto map = road_map();
  const MapIndex index(map);
  const auto curbs = detected_curbs(map, true, 2);
  ASSERT_EQ(curbs.size(), 429u);  // 129 of 429 = 30 % outliers

  std::mt19937_64 rng(42);
  const IcpResult p = probabilistic_icp(index, curbs, {}, ProbabilisticIcpParams{}, rng);
  IcpParams no_rejection;
  no_rejection.max_correspondence = std::numeric_limits<double>::infinity();
  const IcpResult plain = icp(index, curbs, {}, no_rejection);
  const IcpResult gated = icp(index, curbs, {}, IcpParams{});  // default 2 m correspondence gate
  const IcpResult robust = m_icp(index, curbs, {}, MIcpParams{});
  std::printf(
      "probabilistic ICP: %.4f m %.4f deg outliers %.3f | plain ICP: %.4f m %.4f deg | "
      "gated ICP: %.4f m %.4f deg | M-ICP: %.4f m %.4f deg\n",
      translation_error(p.t), heading_error_deg(p.t), p.outlier_ratio, translation_error(plain.t),
      heading_error_deg(plain.t), translation_error(gated.t), heading_error_deg(gated.t), translation_error(robust.t),
      heading_error_deg(robust.t));
  EXPECT_LT(translation_error(p.t), 0.02);
  EXPECT_LT(heading_error_deg(p.t), 0.1);
  EXPECT_NEAR(p.outlier_ratio, 129.0 / 429.0, 0.02);  // the vans and the scattered returns, no more
  EXPECT_GT(translation_error(plain.t), 0.10);
  EXPECT_GT(translation_error(gated.t), 0.10);  // a fixed gate is no cure: the vans are inside it
}

TEST(ProbabilisticIcp, SameSeedSameResult) {
  const auto map = road_map();
  const MapIndex index(map);
  const auto curbs = detected_curbs(map, true, 3);
  std::mt19937_64 a(5), b(5);
  const IcpResult ra = probabilistic_icp(index, curbs, {}, ProbabilisticIcpParams{}, a);
  const IcpResult rb = probabilistic_icp(index, curbs, {}, ProbabilisticIcpParams{}, b);
  EXPECT_EQ(ra.t.x, rb.t.x);
  EXPECT_EQ(ra.t.y, rb.t.y);
  EXPECT_EQ(ra.t.yaw, rb.t.yaw);
  EXPECT_EQ(ra.inliers, rb.inliers);
  EXPECT_EQ(a(), b());  // and the engine advanced identically
}

// Eq. 13 reading: the draw with the fewest outliers dominates; several worse draws must not drag it.
TEST(ProbabilisticIcp, FusionFavoursTheDrawWithFewestOutliers) {
  std::vector<IcpHypothesis> h{{kTruth, 0.30}};
  for (int k = 0; k < 5; ++k) h.push_back({{kTruth.x + 1.0, kTruth.y - 0.8, kTruth.yaw + 2 * kDeg}, 0.45});
  const Pose2d fused = fuse_hypotheses(h, 1.0 / 429);
  EXPECT_LT(translation_error(fused), 0.01);
  EXPECT_LT(heading_error_deg(fused), 0.01);
  // Without the sharp weighting (temperature -> infinity: a plain mean) the bad draws win: the test
  // above really depends on the weighting.
  EXPECT_GT(translation_error(fuse_hypotheses(h, 1e9)), 1.0);
  // Draws that agree within noise (equal outlier ratios) are averaged evenly.
  const Pose2d even = fuse_hypotheses({{{0, 0, 0}, 0.3}, {{0.02, 0, 0}, 0.3}}, 1.0 / 429);
  EXPECT_NEAR(even.x, 0.01, 1e-12);
}

TEST(ProbabilisticIcp, FusionAveragesHeadingsAsAngles) {
  const Pose2d fused = fuse_hypotheses({{{0, 0, 179 * kDeg}, 0.2}, {{0, 0, -179 * kDeg}, 0.2}}, 1.0 / 429);
  EXPECT_NEAR(std::abs(fused.yaw), std::numbers::pi, 1e-9);  // 180 deg, not the 0 of a plain mean
}

TEST(ProbabilisticIcp, EmptyAndTinyInputs) {
  const auto map = road_map();
  const MapIndex index(map);
  std::mt19937_64 rng(1);
  const Pose2d initial{0.3, -0.2, 0.01};

  IcpResult r = probabilistic_icp(index, {}, initial, ProbabilisticIcpParams{}, rng);
  EXPECT_EQ(r.t.x, initial.x);
  EXPECT_EQ(r.outlier_ratio, 1.0);
  EXPECT_EQ(r.inliers, 0u);
  r = probabilistic_icp(MapIndex({}), {{1, 1}}, initial, ProbabilisticIcpParams{}, rng);
  EXPECT_EQ(r.t.y, initial.y);
  EXPECT_EQ(r.outlier_ratio, 1.0);
  EXPECT_EQ(icp(MapIndex({}), {{1, 1}}, initial, IcpParams{}).outlier_ratio, 1.0);
  EXPECT_EQ(m_icp(index, {}, initial, MIcpParams{}).outlier_ratio, 1.0);

  // One curb: a pure translation onto the nearest map point; five (< n_p): all are used.
  r = probabilistic_icp(index, {{3.04, 0.3}}, {}, ProbabilisticIcpParams{}, rng);
  EXPECT_EQ(r.inliers, 1u);
  EXPECT_LT(r.rmse, 1e-9);
  const std::vector<Eigen::Vector2d> five{{-3, 0.2}, {0, 0.2}, {3, 0.2}, {-20, 10.2}, {20, 10.2}};
  r = probabilistic_icp(index, five, {}, ProbabilisticIcpParams{}, rng);
  EXPECT_EQ(r.inliers, 5u);
  EXPECT_NEAR(r.t.y, -0.2, 0.02);
  EXPECT_EQ(r.iterations, 1);
}

}  // namespace
}  // namespace lidarloop
