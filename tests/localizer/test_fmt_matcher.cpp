// The FMT baseline (the paper's `fmt`, ref. [36]): recovery of a known pose error on a synthetic
// T-junction, pure translation to a cell, each sign convention on its own, a rotation near 180 degrees
// (the magnitude spectrum's ambiguity), and refusal of empty, non-finite and unrelated input.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include "common/units.hpp"
#include "localizer/fmt_matcher.hpp"

namespace lidarloop {
namespace {

constexpr double kSpacing = 0.1;  // m between map curb points (the map's resolution)

// The junction sits far from the local origin, so a rotation about the wrong point shows.
const Eigen::Vector2d kOrigin(150.0, -80.0);
constexpr double kHalfRoad = 3.5;                    // two curbs 7 m apart along x
constexpr double kRoadMin = -40, kRoadMax = 40;      // m along x, past the grid's +-25 m
constexpr double kSideLeft = 1.0, kSideRight = 8.0;  // a side road going north, 7 m wide
constexpr double kSideEnd = 30.0;                    // m north of the main road's axis

// The vehicle's true position (relative to kOrigin): on the main road, short of the junction.
const Eigen::Vector2d kVehicle(-2.0, -1.0);
constexpr double kScanRange = 20.0;  // m: curbs detected around the vehicle (beam model +-25 m)
constexpr double kCurbNoise = 0.03;  // m, detected curbs about the mapped line
constexpr int kScanStride = 2;       // detected curbs are sparser than the map's points

// Tolerances of the brief: one or two cells, half a degree.
constexpr double kPositionTolerance = 0.1;
constexpr double kHeadingTolerance = 0.5 * kDeg;

void add_line(std::vector<Eigen::Vector2d>& out, Eigen::Vector2d a, Eigen::Vector2d b) {
  const int n = static_cast<int>(std::round((b - a).norm() / kSpacing));
  for (int i = 0; i <= n; ++i) out.push_back(kOrigin + a + (b - a) * (double(i) / n));
}

std::vector<Eigen::Vector2d> junction_map() {
  std::vector<Eigen::Vector2d> map;
  add_line(map, {kRoadMin, -kHalfRoad}, {kRoadMax, -kHalfRoad});  // south curb, unbroken
  add_line(map, {kRoadMin, kHalfRoad}, {kSideLeft, kHalfRoad});   // north curb, west of the side road
  add_line(map, {kSideRight, kHalfRoad}, {kRoadMax, kHalfRoad});  // north curb, east of it
  add_line(map, {kSideLeft, kHalfRoad}, {kSideLeft, kSideEnd});   // the side road's curbs
  add_line(map, {kSideRight, kHalfRoad}, {kSideRight, kSideEnd});
  return map;
}

// A pose error of the prior, as the correction that undoes it: turn by `theta` about the true vehicle
// position, then shift by (x, y). The prior is then |(x, y)| from the truth, as after a GPS error, and
// the map window around the prior still covers the junction whatever the heading error.
Pose2d correction_about_vehicle(double x, double y, double theta) {
  const Eigen::Vector2d v = kOrigin + kVehicle;
  const Pose2d to_vehicle{-v.x(), -v.y(), 0}, turn{0, 0, theta}, back{v.x() + x, v.y() + y, 0};
  return back.compose(turn.compose(to_vehicle));
}

struct Case {
  Pose2d correction;                         // what fmt_match should find
  std::vector<Eigen::Vector2d> curbs_world;  // detected curbs placed in the world at the prior pose
  Eigen::Vector2d prior;                     // the prior position: the grid centre
  Eigen::Vector2d truth;                     // where the correction must take the prior
};

// Detected curbs: every kScanStride-th map point within kScanRange of the vehicle, with noise, placed
// in the world with the prior pose, i.e. moved by the inverse of the correction.
Case make_case(const std::vector<Eigen::Vector2d>& map, double x, double y, double theta) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, kCurbNoise);
  Case c;
  c.correction = correction_about_vehicle(x, y, theta);
  const Pose2d to_prior = c.correction.inverse();
  c.truth = kOrigin + kVehicle;
  c.prior = to_prior.apply(c.truth);
  for (size_t i = 0; i < map.size(); i += kScanStride) {
    if ((map[i] - c.truth).norm() > kScanRange) continue;
    c.curbs_world.push_back(to_prior.apply(map[i] + Eigen::Vector2d(noise(rng), noise(rng))));
  }
  return c;
}

// The corrected position (the correction applied to the prior) and heading, which is what the pose
// filter uses, and the transform as a whole: curbs 20 m from the vehicle must land where they should.
void expect_recovered(const FmtResult& r, const Case& c) {
  ASSERT_TRUE(r.ok) << "response " << r.response;
  const Eigen::Vector2d corrected = r.correction.apply(c.prior);
  EXPECT_NEAR(corrected.x(), c.truth.x(), kPositionTolerance);
  EXPECT_NEAR(corrected.y(), c.truth.y(), kPositionTolerance);
  EXPECT_NEAR(wrap_angle(r.correction.yaw - c.correction.yaw), 0.0, kHeadingTolerance)
      << "heading " << r.correction.yaw / kDeg << " deg";
  const Eigen::Vector2d far_curb = c.prior + Eigen::Vector2d(kScanRange, 0);
  EXPECT_LT((r.correction.apply(far_curb) - c.correction.apply(far_curb)).norm(), 2 * kPositionTolerance);
}

TEST(FmtMatcher, RecoversTranslationAndRotation) {
  const auto map = junction_map();
  const Case c = make_case(map, 0.6, -0.4, 2.0 * kDeg);
  const FmtResult r = fmt_match(c.curbs_world, map, c.prior);
  expect_recovered(r, c);
  EXPECT_GE(r.response, FmtParams{}.min_response);
}

TEST(FmtMatcher, RecoversPureTranslationToOneCell) {
  const auto map = junction_map();
  const Case c = make_case(map, 1.3, -0.7, 0.0);
  const FmtResult r = fmt_match(c.curbs_world, map, c.prior);
  ASSERT_TRUE(r.ok);
  // The pose moves by the shift. (Not the transform's x and y: those are about the local origin,
  // 170 m away, where a tenth of a degree of rotation is 0.3 m.)
  const double cell = FmtParams{}.cell_m;
  const Eigen::Vector2d moved = r.correction.apply(c.prior) - c.prior;
  EXPECT_NEAR(moved.x(), 1.3, cell);
  EXPECT_NEAR(moved.y(), -0.7, cell);
  EXPECT_NEAR(r.correction.yaw, 0.0, kHeadingTolerance);
}

// Each axis and each sense of rotation on its own: a swapped x and y, a row direction taken as +y, or
// a rotation read the wrong way round each fail here.
TEST(FmtMatcher, SignConventions) {
  const auto map = junction_map();
  constexpr double kShift = 0.8, kTurn = 3.0 * kDeg;
  struct Error {
    double x, y, yaw;
  };
  for (const Error e : {Error{kShift, 0, 0}, Error{0, kShift, 0}, Error{0, 0, kTurn}, Error{0, 0, -kTurn}}) {
    SCOPED_TRACE(testing::Message() << "error " << e.x << " m, " << e.y << " m, " << e.yaw / kDeg << " deg");
    const Case c = make_case(map, e.x, e.y, e.yaw);
    const FmtResult r = fmt_match(c.curbs_world, map, c.prior);
    expect_recovered(r, c);
    if (e.yaw == 0) {  // a pure shift: the pose must move by it, in this direction
      const Eigen::Vector2d moved = r.correction.apply(c.prior) - c.prior;
      EXPECT_NEAR(moved.x(), e.x, kPositionTolerance);
      EXPECT_NEAR(moved.y(), e.y, kPositionTolerance);
    } else {
      EXPECT_GT(r.correction.yaw * e.yaw, 0) << "rotation read the wrong way round";
    }
  }
}

// A heading off by nearly a half turn: the magnitude spectrum cannot tell it from a small one; the
// translation step (the side road is on one side of the main road only) must.
TEST(FmtMatcher, ResolvesTheHalfTurnAmbiguity) {
  const auto map = junction_map();
  const Case c = make_case(map, -0.5, 0.3, 175.0 * kDeg);
  expect_recovered(fmt_match(c.curbs_world, map, c.prior), c);
}

TEST(FmtMatcher, RefusesEmptyAndNonFiniteInput) {
  const auto map = junction_map();
  const Case c = make_case(map, 0.6, -0.4, 2.0 * kDeg);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(fmt_match({}, map, c.prior).ok);
  EXPECT_FALSE(fmt_match(c.curbs_world, {}, c.prior).ok);
  EXPECT_FALSE(fmt_match({}, {}, c.prior).ok);
  EXPECT_FALSE(fmt_match(std::vector<Eigen::Vector2d>(100, Eigen::Vector2d(nan, 1.0)), map, c.prior).ok);
  EXPECT_FALSE(fmt_match(c.curbs_world, map, Eigen::Vector2d(nan, 0.0)).ok);
  EXPECT_FALSE(fmt_match(c.curbs_world, map, Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0.0)).ok);
  // Too few points (all else fine), and every curb off the grid.
  const std::vector<Eigen::Vector2d> few(c.curbs_world.begin(), c.curbs_world.begin() + 3);
  EXPECT_FALSE(fmt_match(few, map, c.prior).ok);
  EXPECT_FALSE(fmt_match(c.curbs_world, map, c.prior + Eigen::Vector2d(1000, 0)).ok);

  // Degenerate but finite input: an answer, finite whatever it is.
  const std::vector<Eigen::Vector2d> one_spot(50, c.prior), one_line(map.begin(), map.begin() + 200);
  for (const auto* curbs : {&one_spot, &one_line}) {
    const Pose2d t = fmt_match(*curbs, map, c.prior).correction;
    EXPECT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.yaw));
  }

  // A few non-finite curbs among good ones are skipped, not fatal.
  auto dirty = c.curbs_world;
  dirty.emplace_back(nan, 0.0);
  dirty.emplace_back(0.0, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(fmt_match(dirty, map, c.prior).ok);
}

// Curbs that have nothing to do with the map must not pass as a match.
TEST(FmtMatcher, RejectsUnrelatedCurbs) {
  const auto map = junction_map();
  const Case c = make_case(map, 0, 0, 0);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-kScanRange, kScanRange);
  std::vector<Eigen::Vector2d> scatter;
  for (size_t i = 0; i < c.curbs_world.size(); ++i) scatter.push_back(c.prior + Eigen::Vector2d(u(rng), u(rng)));
  const FmtResult r = fmt_match(scatter, map, c.prior);
  EXPECT_FALSE(r.ok) << "response " << r.response;
  EXPECT_LT(r.response, FmtParams{}.min_response);
}

TEST(FmtMatcher, RejectsBadParams) {
  const std::vector<Eigen::Vector2d> pts{{0, 0}};
  const auto bad = [&](auto change) {
    FmtParams p;
    change(p);
    EXPECT_THROW(fmt_match(pts, pts, {0, 0}, p), std::invalid_argument);
  };
  bad([](FmtParams& p) { p.size_cells = 4; });
  bad([](FmtParams& p) { p.size_cells = 1 << 20; });
  bad([](FmtParams& p) { p.cell_m = 0; });
  bad([](FmtParams& p) { p.cell_m = std::numeric_limits<double>::quiet_NaN(); });
  bad([](FmtParams& p) { p.blur_sigma_cells = -1; });
  bad([](FmtParams& p) { p.angle_bins = 2; });
  bad([](FmtParams& p) { p.min_radius_fraction = 0.6; });
  bad([](FmtParams& p) { p.max_radius_fraction = 1.5; });
  bad([](FmtParams& p) { p.min_points = 0; });
  bad([](FmtParams& p) { p.min_response = 2; });
}

}  // namespace
}  // namespace lidarloop
