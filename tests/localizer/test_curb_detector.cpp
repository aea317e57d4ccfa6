// Single-frame curb detection (paper 2.2.1) on synthetic scans of a straight road whose curbs are
// known: the fast detector (localizer/curb_detector.cpp) must find exactly the curbs of its oracle,
// the plain detector in reference_curb_detector.hpp, on hundreds of seeded random roads and on the
// edge cases one by one; and on the clean cases, the curbs where the road has them.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "localizer/curb_detector.hpp"
#include "reference_curb_detector.hpp"

namespace lidarloop::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kAzimuthStep = 0.0029;  // rad: the HDL-32E's at 10 Hz, which the detector's gap test assumes

struct Scan {
  std::vector<Eigen::Vector3d> points;
  std::vector<uint16_t> rings;

  void add(const Eigen::Vector3d& p, uint16_t ring) {
    points.push_back(p);
    rings.push_back(ring);
  }
};

// Both detectors on one scan: the fast one must return the reference's curbs exactly. Returns them.
std::vector<Eigen::Vector2d> expect_same_curbs(const Scan& scan, const CurbDetectorParams& params = {}) {
  const std::vector<Eigen::Vector2d> reference = reference_detect_curbs(scan.points, scan.rings, params);
  EXPECT_EQ(curb_difference(detect_curbs(scan.points, scan.rings, params), reference), "");
  return reference;
}

// ---- The synthetic road ----

// One side's curb, at y = +distance (left) or y = -distance (right) of the road's centreline y = 0.
struct CurbSide {
  double distance = 4.5;  // m from the centreline to the foot of the curb face
  double height = 0.15;   // m from the road's edge up to the sidewalk
  double face_width = 0;  // m across which the face rises: 0 for an upright stone, more for a sloped curb
};

// A vehicle's body as low rings see it: a flat top `height` above the ground over its footprint.
struct Obstacle {
  Eigen::Vector2d min, max;
  double height;
};

// A straight road along x, its two curbs and the flat sidewalks beyond. The road may fall towards its
// curbs (cross_fall, m/m) and climb along x (grade, m/m). Between ramp_from and ramp_to the right curb
// is a driveway ramp: its rise spread over ramp_length metres.
struct Road {
  CurbSide left, right;
  double cross_fall = 0, grade = 0;
  double ramp_from = 0, ramp_to = 0, ramp_length = 0;
  std::vector<Obstacle> obstacles;

  double height(double x, double y) const {
    const CurbSide& side = y >= 0 ? left : right;
    const double across = std::abs(y);
    double z = grade * x - cross_fall * std::min(across, side.distance);
    double face = side.face_width;
    if (y < 0 && x >= ramp_from && x <= ramp_to) face = std::max(face, ramp_length);
    if (across > side.distance)
      z += face > 0 ? side.height * std::min(1.0, (across - side.distance) / face) : side.height;
    for (const Obstacle& o : obstacles)
      if (x >= o.min.x() && x <= o.max.x() && y >= o.min.y() && y <= o.max.y()) z = std::max(z, o.height);
    return z;
  }
};

// A spinning multi-laser sensor reduced to what the detector reads: each ring is a circle of constant
// ground range around the sensor, and every azimuth step fires all rings (in firing order, not ring
// order), so the scan interleaves the rings as a real one does.
struct Sensor {
  Eigen::Vector2d position{1.2, 0.0};  // in the vehicle frame
  double height = 1.9;                 // m above the ground
  std::vector<double> ranges;          // m: where each ring meets flat ground at z = 0
  std::vector<uint16_t> ring_ids;      // the ring number each range is reported under
  double azimuth_from = -M_PI, azimuth_to = M_PI, azimuth_step = kAzimuthStep;
  double range_noise = 0, height_noise = 0;  // m, standard deviations
  double dropout = 0;                        // probability that a return is missing
  double nan_fraction = 0;                   // probability that a return is reported as NaN (a driver's placeholder)
  // A raised surface meets a beam short of its ground range, as on a real sensor, so a ring bends
  // inwards over a sidewalk (and its points crowd or gap at the curb). Approximate: one correction.
  bool parallax = false;
};

Scan scan_road(const Road& road, const Sensor& sensor, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0, 1);  // scaled: a normal distribution may not have zero spread
  std::bernoulli_distribution dropped(sensor.dropout), nan(sensor.nan_fraction);
  Scan scan;
  for (double a = sensor.azimuth_from; a <= sensor.azimuth_to; a += sensor.azimuth_step) {
    const Eigen::Vector2d direction(std::cos(a), std::sin(a));
    for (size_t k = 0; k < sensor.ranges.size(); ++k) {
      double range = sensor.ranges[k];
      if (sensor.range_noise > 0) range += sensor.range_noise * normal(rng);
      Eigen::Vector2d xy = sensor.position + range * direction;
      double z = road.height(xy.x(), xy.y());
      if (sensor.parallax) {
        range *= 1 - z / sensor.height;
        xy = sensor.position + range * direction;
        z = road.height(xy.x(), xy.y());
      }
      if (sensor.height_noise > 0) z += sensor.height_noise * normal(rng);
      if (sensor.dropout > 0 && dropped(rng)) continue;
      if (sensor.nan_fraction > 0 && nan(rng)) {
        scan.add(Eigen::Vector3d(kNaN, kNaN, kNaN), sensor.ring_ids[k]);
        continue;
      }
      scan.add(Eigen::Vector3d(xy.x(), xy.y(), z), sensor.ring_ids[k]);
    }
  }
  return scan;
}

// ---- Random cases ----

struct Case {
  Road road;
  Sensor sensor;
  CurbDetectorParams params;
  std::string description;  // enough to tell the case in a failure message
};

Case random_case(std::mt19937_64& rng) {
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  auto chance = [&](double p) { return std::bernoulli_distribution(p)(rng); };
  auto integer = [&](int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); };
  auto pick = [&](const std::vector<double>& values) { return values[size_t(integer(0, int(values.size()) - 1))]; };
  Case c;
  std::ostringstream d;
  // Heights below, at, within and above the detector's 5-30 cm: the limits themselves test rounding.
  for (CurbSide* side : {&c.road.left, &c.road.right}) {
    side->distance = uniform(1.5, 12.0);
    side->height =
        chance(0.7) ? pick({0, 0.02, 0.05, 0.08, 0.1, 0.12, 0.15, 0.18, 0.22, 0.3, 0.35, 0.6}) : uniform(0.0, 0.45);
    side->face_width = chance(0.5) ? 0.0 : uniform(0.02, 0.6);
    d << "curb " << side->height << " m high at " << side->distance << " m, face " << side->face_width << " m; ";
  }
  if (chance(0.5)) c.road.cross_fall = uniform(-0.03, 0.03);
  if (chance(0.5)) c.road.grade = uniform(-0.06, 0.06);
  d << "cross fall " << c.road.cross_fall << ", grade " << c.road.grade << "; ";
  if (chance(0.25)) {
    c.road.ramp_from = uniform(-15, 10);
    c.road.ramp_to = c.road.ramp_from + uniform(3, 15);
    c.road.ramp_length = uniform(0.4, 3.0);
    d << "ramp x " << c.road.ramp_from << " to " << c.road.ramp_to << " over " << c.road.ramp_length << " m; ";
  }
  for (int k = integer(0, 3); k > 0; --k) {
    const Eigen::Vector2d centre(uniform(-15, 15), uniform(-c.road.right.distance, c.road.left.distance));
    const Eigen::Vector2d half(uniform(1.5, 2.5), uniform(0.7, 1.0));
    c.road.obstacles.push_back({centre - half, centre + half, uniform(0.1, 1.5)});
    d << "obstacle at (" << centre.x() << ", " << centre.y() << ") " << c.road.obstacles.back().height << " m; ";
  }
  // Rings: mostly where a curb can be seen, some nearer than the sensor's 1 m or beyond max_range.
  const int rings = integer(1, 20);
  for (int k = 0; k < rings; ++k) {
    c.sensor.ranges.push_back(chance(0.9) ? uniform(1.5, 22) : uniform(0.3, 32));
    // Usually distinct ids in a scrambled firing order; sometimes two rings under one id, or ids past 63.
    c.sensor.ring_ids.push_back(uint16_t(chance(0.05) ? integer(64, 70) : chance(0.05) ? 0 : (k * 37 + 11) % 64));
  }
  if (chance(0.6)) {
    c.sensor.azimuth_from = uniform(-M_PI, M_PI);
    // Down to a handful of points: very short rings, single points.
    c.sensor.azimuth_to = c.sensor.azimuth_from + (chance(0.2) ? uniform(0, 0.02) : uniform(0.05, 2.0));
  }
  c.sensor.azimuth_step = kAzimuthStep * (chance(0.7) ? 1.0 : uniform(0.3, 5.0));
  c.sensor.range_noise = pick({0, 0, 0.005, 0.02});
  c.sensor.height_noise = pick({0, 0, 0.002, 0.005, 0.01, 0.02, 0.03});  // 0.02: as rough as a road may be
  c.sensor.dropout = pick({0, 0, 0.01, 0.1, 0.4});
  c.sensor.nan_fraction = pick({0, 0, 0.01, 0.1});
  c.sensor.parallax = chance(0.5);
  d << rings << " rings, azimuth " << c.sensor.azimuth_from << " to " << c.sensor.azimuth_to << " by "
    << c.sensor.azimuth_step << ", noise " << c.sensor.range_noise << "/" << c.sensor.height_noise << " m, dropout "
    << c.sensor.dropout << ", NaN " << c.sensor.nan_fraction << (c.sensor.parallax ? ", parallax" : "");
  // Other parameters now and then: both detectors read the same struct, all of it.
  if (chance(0.2)) {
    CurbDetectorParams& p = c.params;
    p.min_height = uniform(0.02, 0.1);
    p.max_height = uniform(0.15, 0.5);
    p.step_length = uniform(0.05, 1.0);
    p.flat_length = uniform(0.1, 1.5);
    p.max_flat_roughness = pick({0, 0.005, 0.02, 0.05, 0.2});
    p.max_range = uniform(5, 40);
    p.max_ground_height = uniform(0.1, 2.0);
    d << "; params " << p.min_height << ", " << p.max_height << ", " << p.step_length << ", " << p.flat_length << ", "
      << p.max_flat_roughness << ", " << p.max_range << ", " << p.max_ground_height;
  }
  c.description = d.str();
  return c;
}

TEST(CurbDetector, FindsTheOraclesCurbsOnRandomRoads) {
  constexpr int kCases = 400;
  constexpr uint64_t kSeed = 20261123;
  int with_curbs = 0;
  size_t curbs = 0, points = 0;
  for (int k = 0; k < kCases; ++k) {
    // A seed per case: a failing case can be rerun on its own.
    std::mt19937_64 rng(kSeed + uint64_t(k));
    const Case c = random_case(rng);
    const Scan scan = scan_road(c.road, c.sensor, rng);
    SCOPED_TRACE("case " + std::to_string(k) + ": " + c.description);
    const auto found = expect_same_curbs(scan, c.params);
    with_curbs += !found.empty();
    curbs += found.size();
    points += scan.points.size();
  }
  std::cout << "[ figures  ] " << kCases << " synthetic scans, " << points << " points: " << curbs << " curbs in "
            << with_curbs << " scans, the same in both detectors\n";
  // Not vacuous: many scans must hold curbs, and many must not.
  EXPECT_GE(with_curbs, kCases / 4);
  EXPECT_LE(with_curbs, kCases * 9 / 10);
  EXPECT_GE(curbs, 5000u);
}

// ---- The clean road, where the truth is known ----

// Full rings at 5 to 15 m on a flat road with upright curbs at y = +-4.5 m (the sensor is on y = 0).
Sensor clean_rings() {
  Sensor s;
  for (int k = 0; k < 11; ++k) {
    s.ranges.push_back(5.0 + k);
    s.ring_ids.push_back(uint16_t(2 * k));
  }
  return s;
}

TEST(CurbDetector, FindsEveryCrossingOfACleanCurbAndNothingElse) {
  std::mt19937_64 rng(1);
  const Road road;  // 15 cm curbs at 4.5 m
  const Sensor sensor = clean_rings();
  const auto curbs = expect_same_curbs(scan_road(road, sensor, rng));
  // The foot is the last road point before the rise: on the road side, within a point spacing.
  constexpr double kSpacing = 15.0 * kAzimuthStep;
  for (const auto& c : curbs) {
    EXPECT_LE(std::abs(c.y()), 4.5);
    EXPECT_GT(std::abs(c.y()), 4.5 - kSpacing) << c.transpose();
  }
  // Each ring crosses each curb line twice, once on either side of the sensor.
  for (double range : sensor.ranges)
    for (double y : {-4.5, 4.5})
      for (double sign : {-1.0, 1.0}) {
        const Eigen::Vector2d crossing(sensor.position.x() + sign * std::sqrt(range * range - y * y), y);
        bool found = false;
        for (const auto& c : curbs) found |= (c - crossing).norm() < 2 * kSpacing;
        EXPECT_TRUE(found) << "ring " << range << " m, crossing " << crossing.transpose();
      }
}

TEST(CurbDetector, FindsNoCurbWhereTheStepIsNoCurb) {
  std::mt19937_64 rng(2);
  const Sensor sensor = clean_rings();
  for (double height : {0.0, 0.03, 0.45, 1.0}) {  // no step, road texture, too high for a curb, a wall
    Road road;
    road.left.height = road.right.height = height;
    SCOPED_TRACE("curb " + std::to_string(height) + " m high");
    EXPECT_TRUE(expect_same_curbs(scan_road(road, sensor, rng)).empty());
  }
  Road ramps;  // a gentle rise is a ramp, not a curb
  ramps.left.face_width = ramps.right.face_width = 3.0;
  EXPECT_TRUE(expect_same_curbs(scan_road(ramps, sensor, rng)).empty());
}

// ---- Edge cases, one by one ----

// One ring along a circle of `range` around the origin, starting at azimuth 0, with z given per point.
Scan ring_of(size_t n, double range, const std::function<double(size_t)>& z, uint16_t ring = 5,
             double step = kAzimuthStep) {
  Scan s;
  for (size_t k = 0; k < n; ++k)
    s.add(Eigen::Vector3d(range * std::cos(double(k) * step), range * std::sin(double(k) * step), z(k)), ring);
  return s;
}

// A 15 cm step after `road` points of a ring at 8 m. The points are 2.32 cm apart, so with the default
// parameters a flat stretch takes 23 points (22 gaps reach 0.5 m) and a rise 18 gaps (0.4 m).
Scan step_ring(size_t road, size_t walk, double height = 0.15, uint16_t ring = 5) {
  return ring_of(
      road + walk, 8.0, [=](size_t k) { return k < road ? 0.0 : height; }, ring);
}

struct EdgeCase {
  std::string name;
  Scan scan;
  CurbDetectorParams params;
  // Where the truth is plain, how many distinct curb points (-1: only the oracle says). Distinct: a
  // rise seen against the ring's order is found again from each road point within step_length of it,
  // at the same foot each time; that is the oracle's behaviour, so the fast detector's too.
  int expected_feet = -1;
};

std::vector<EdgeCase> edge_cases() {
  std::vector<EdgeCase> cases;
  const CurbDetectorParams defaults;
  auto add = [&](std::string name, Scan scan, int expected = -1, CurbDetectorParams params = {}) {
    cases.push_back({std::move(name), std::move(scan), params, expected});
  };
  add("empty scan", {}, 0);
  add(
      "points without rings",
      [] {
        Scan s = step_ring(40, 40);
        s.rings.clear();
        return s;
      }(),
      0);
  add(
      "rings without points",
      [] {
        Scan s = step_ring(40, 40);
        s.points.clear();
        return s;
      }(),
      0);
  add("fewer rings than points: the curb is cut off", [] {
    Scan s = step_ring(40, 40);
    s.rings.resize(45);
    return s;
  }());
  add(
      "more rings than points",
      [] {
        Scan s = step_ring(40, 40);
        s.rings.resize(200, 5);
        return s;
      }(),
      1);
  add("a single point", ring_of(1, 8.0, [](size_t) { return 0.0; }), 0);
  add("four points", step_ring(2, 2), 0);
  add("five points", step_ring(2, 3), 0);
  add("six points", step_ring(3, 3), 0);
  add("a ring too short for road, rise and sidewalk", step_ring(10, 10), 0);
  // Road (23 points), rise (18 gaps) and sidewalk (23 points) need 63 points at least.
  add("a ring just long enough", step_ring(23, 40), 1);
  add("a ring one point too short", step_ring(23, 39), 0);
  add("the clean step", step_ring(40, 40), 1);
  add(
      "the step seen the other way round",
      [] {
        Scan s = step_ring(40, 40);
        std::reverse(s.points.begin(), s.points.end());
        return s;
      }(),
      1);
  add("a step down and up again: a sunk stretch",
      ring_of(120, 8.0, [](size_t k) { return k < 40 || k >= 80 ? 0.15 : 0.0; }), 2);
  add("a chamfered curb: one point at exactly half min_height, which is no longer road",
      ring_of(80, 8.0, [&](size_t k) { return k < 40    ? 0.0
                                              : k == 40 ? defaults.min_height / 2
                                                        : 0.15; }), 1);
  add("a rise of exactly min_height", step_ring(40, 40, defaults.min_height));
  add("a rise just under min_height", step_ring(40, 40, std::nextafter(defaults.min_height, 0.0)), 0);
  add("a rise of exactly max_height", step_ring(40, 40, defaults.max_height));
  add("a rise just over max_height", step_ring(40, 40, std::nextafter(defaults.max_height, 1.0)), 0);
  // The shortest ring with a curb (as above), every fourth point `bump` higher: road and sidewalk hold
  // 6 bumps in 23 points, a spread about the median of bump * sqrt(6 / 23), which for this bump is
  // max_flat_roughness in exact arithmetic. The fast detector's roughness pre-test must not reject
  // what the median test lets through, rounding included.
  const double bump = defaults.max_flat_roughness * std::sqrt(23.0 / 6.0);
  for (const auto& [name, scale_param, feet] : {std::tuple{"just smoother than", 1.0 - 1e-12, 1},
                                                {"as rough as", 1.0, -1},
                                                {"just rougher than", 1.0 + 1e-12, 0}}) {
    const double scale = scale_param;  // a lambda may not capture a structured binding before clang 16
    add(std::string("a road ") + name + " allowed",
        ring_of(63, 8.0, [=](size_t k) { return (k < 23 ? 0.0 : 0.15) + (k % 4 == 1 ? bump * scale : 0.0); }), feet);
  }
  add("one stray return on the road", ring_of(80, 8.0, [](size_t k) { return k == 20  ? 0.08
                                                                             : k < 40 ? 0.0
                                                                                      : 0.15; }),
      1);
  add("all points at one place",
      ring_of(
          50, 8.0, [](size_t) { return 0.0; }, 5, 0.0),
      0);
  add("each point twice", [] {
    Scan s, once = step_ring(40, 40);
    for (size_t k = 0; k < once.points.size(); ++k)
      for (int twice = 0; twice < 2; ++twice) s.add(once.points[k], once.rings[k]);
    return s;
  }());
  add(
      "a gap of missing returns at the curb",
      [] {
        Scan s = step_ring(60, 60);
        s.points.erase(s.points.begin() + 55, s.points.begin() + 65);
        s.rings.erase(s.rings.begin() + 55, s.rings.begin() + 65);
        return s;
      }(),
      0);
  add(
      "NaN in the middle of the road",
      [] {
        Scan s = step_ring(40, 40);
        s.points[20].z() = kNaN;
        s.points[21].x() = kNaN;
        return s;
      }(),
      1);
  add(
      "infinite points",
      [] {
        Scan s = step_ring(40, 40);
        s.points[10] = Eigen::Vector3d(kInf, 0, 0);
        s.points[50] = Eigen::Vector3d(0, 0, -kInf);
        return s;
      }(),
      1);
  add(
      "all NaN",
      [] {
        Scan s = step_ring(40, 40);
        for (auto& p : s.points) p.setConstant(kNaN);
        return s;
      }(),
      0);
  add("ring 63", step_ring(40, 40, 0.15, 63), 1);
  add("ring 64 is no ring", step_ring(40, 40, 0.15, 64), 0);
  add("ring 65535 is no ring", step_ring(40, 40, 0.15, 65535), 0);
  add(
      "two rings interleaved",
      [] {
        const Scan a = step_ring(40, 40, 0.15, 3), b = ring_of(
                                                       80, 12.0, [](size_t k) { return k < 50 ? 0.0 : 0.1; }, 9);
        Scan s;
        for (size_t k = 0; k < 80; ++k) {
          s.add(a.points[k], a.rings[k]);
          s.add(b.points[k], b.rings[k]);
        }
        return s;
      }(),
      2);
  add("at exactly 1 m and max_range", [&] {
    Scan s = ring_of(
        400, 1.0, [](size_t k) { return k < 200 ? 0.0 : 0.15; }, 1, 0.0125);
    const Scan far = ring_of(
        80, defaults.max_range, [](size_t k) { return k < 40 ? 0.0 : 0.15; }, 2, 0.0012);
    s.points.insert(s.points.end(), far.points.begin(), far.points.end());
    s.rings.insert(s.rings.end(), far.rings.begin(), far.rings.end());
    return s;
  }());
  add("a sidewalk at exactly max_ground_height", step_ring(40, 40, defaults.max_ground_height), -1, [] {
    CurbDetectorParams p;
    p.max_height = 1.0;
    return p;
  }());
  add("a car body: a step too high", ring_of(200, 6.0, [](size_t k) { return k >= 60 && k < 140 ? 0.45 : 0.0; }), 0);
  add("a car body low enough to read as a curb at both ends",
      ring_of(200, 6.0, [](size_t k) { return k >= 60 && k < 140 ? 0.25 : 0.0; }), 2);
  add("negative heights", ring_of(80, 8.0, [](size_t k) { return k < 40 ? -0.6 : -0.45; }), 1);
  // Parameters at their edges; the fast detector takes care of NaN and overflowing arc lengths.
  auto with = [](std::function<void(CurbDetectorParams&)> set) {
    CurbDetectorParams p;
    set(p);
    return p;
  };
  add(
      "arc lengths exactly the step and flat lengths",
      [] {
        // Points 1/8 m apart on a straight line, so arc lengths are exact: road 0 to 4, sidewalk 5 to 11.
        // Point 4's road (0 to 4), rise (to 7) and sidewalk (7 to 11) each reach their length exactly.
        Scan s;
        for (int k = 0; k < 12; ++k) s.add(Eigen::Vector3d(5 + 0.125 * k, 3, k < 5 ? 0.0 : 0.15), 7);
        return s;
      }(),
      1, with([](auto& p) { p.step_length = 0.375; }));
  add("zero step and flat lengths", step_ring(40, 40), -1, with([](auto& p) { p.step_length = p.flat_length = 0; }));
  add("zero roughness allowed", step_ring(40, 40), 1, with([](auto& p) { p.max_flat_roughness = 0; }));
  add("infinite lengths", step_ring(40, 40), 0, with([](auto& p) { p.step_length = p.flat_length = kInf; }));
  add("NaN step length", step_ring(40, 40), -1, with([](auto& p) { p.step_length = kNaN; }));
  add("NaN flat length", step_ring(40, 40), -1, with([](auto& p) { p.flat_length = kNaN; }));
  add("NaN heights and range", step_ring(40, 40), -1, with([](auto& p) {
        p.min_height = p.max_height = p.max_flat_roughness = kNaN;
        p.max_range = p.max_ground_height = kNaN;
      }));
  add("arc lengths that overflow",
      ring_of(
          80, 1e306, [](size_t k) { return k < 40 ? 0.0 : 0.15; }, 5, 0.5),
      -1, with([](auto& p) { p.max_range = kInf; }));
  add("min_height above max_height", step_ring(40, 40), 0,
      with([](auto& p) { std::swap(p.min_height, p.max_height); }));
  return cases;
}

TEST(CurbDetector, FindsTheOraclesCurbsInEachEdgeCase) {
  const std::vector<EdgeCase> cases = edge_cases();
  size_t total = 0;
  for (const EdgeCase& c : cases) {
    SCOPED_TRACE(c.name);
    const auto curbs = expect_same_curbs(c.scan, c.params);
    total += curbs.size();
    if (c.expected_feet >= 0) {
      std::vector<std::pair<double, double>> feet;
      for (const auto& f : curbs) feet.emplace_back(f.x(), f.y());
      std::sort(feet.begin(), feet.end());
      EXPECT_EQ(std::unique(feet.begin(), feet.end()) - feet.begin(), c.expected_feet);
    }
  }
  std::cout << "[ figures  ] " << cases.size() << " edge cases: " << total << " curbs, the same in both detectors\n";
}

}  // namespace
}  // namespace lidarloop::test
