// The map is a survey: the survey error's statistics (Gauss-Markov over distance), the curb layer moved
// by it and measured against the world's own curb lines, the intensity layer placed with the surveyed
// poses, and the survey's settings in the map's cache key. Each check compares with a truth the test
// knows independently (the configured statistics, the world's lines, a map without survey error).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "mapping/mapping_drive.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

struct Moments {
  double mean = 0, sigma = 0;
};

Moments moments(const std::vector<double>& v) {
  double sum = 0, sum2 = 0;
  for (double x : v) sum += x, sum2 += x * x;
  const double n = double(v.size()), mean = sum / n;
  return {mean, std::sqrt(sum2 / n - mean * mean)};
}

// Sample autocorrelation at `lag` samples.
double autocorrelation(const std::vector<double>& v, size_t lag) {
  const Moments m = moments(v);
  double sum = 0;
  for (size_t i = 0; i + lag < v.size(); ++i) sum += (v[i] - m.mean) * (v[i + lag] - m.mean);
  return sum / double(v.size() - lag) / (m.sigma * m.sigma);
}

TEST(SurveyError, GaussMarkovHasTheConfiguredSigmaAndCorrelationAtAnySpacing) {
  SurveyErrorConfig c;
  c.sigma_xy_m = 0.03;
  c.correlation_length_m = 10.0;
  c.heading_sigma_rad = 0.2 * kDeg;
  c.heading_correlation_length_m = 25.0;
  constexpr double kLength = 200'000.0;  // m: 20,000 position correlation lengths
  for (double spacing : {1.0, 0.25}) {
    c.sample_spacing_m = spacing;
    std::mt19937_64 rng(3);
    const SurveyErrorTrack track = simulate_survey_error(c, kLength, rng);
    ASSERT_EQ(track.samples.size(), size_t(kLength / spacing) + 1);
    std::vector<double> east, north, heading;
    for (const Pose2d& e : track.samples) east.push_back(e.x), north.push_back(e.y), heading.push_back(e.yaw);
    for (const auto* axis : {&east, &north}) {
      const Moments m = moments(*axis);
      EXPECT_NEAR(m.sigma, c.sigma_xy_m, 0.03 * c.sigma_xy_m) << "spacing " << spacing;
      EXPECT_NEAR(m.mean, 0.0, 0.1 * c.sigma_xy_m);
      // exp(-|ds| / L): e^-1 at one correlation length, e^-3 at three.
      const size_t lag = size_t(std::lround(c.correlation_length_m / spacing));
      EXPECT_NEAR(autocorrelation(*axis, lag), std::exp(-1.0), 0.03) << "spacing " << spacing;
      EXPECT_NEAR(autocorrelation(*axis, 3 * lag), std::exp(-3.0), 0.03) << "spacing " << spacing;
    }
    const Moments h = moments(heading);
    EXPECT_NEAR(h.sigma, c.heading_sigma_rad, 0.05 * c.heading_sigma_rad);
    const size_t lag = size_t(std::lround(c.heading_correlation_length_m / spacing));
    EXPECT_NEAR(autocorrelation(heading, lag), std::exp(-1.0), 0.04);
    // East and north are independent processes.
    double cross = 0;
    for (size_t i = 0; i < east.size(); ++i) cross += east[i] * north[i];
    EXPECT_NEAR(cross / double(east.size()) / (c.sigma_xy_m * c.sigma_xy_m), 0.0, 0.05);
  }
}

TEST(SurveyError, IsInterpolatedBetweenSamplesAndZeroWithoutSigma) {
  SurveyErrorConfig c;
  c.sample_spacing_m = 2.0;
  std::mt19937_64 rng(1);
  const SurveyErrorTrack track = simulate_survey_error(c, 11.0, rng);
  ASSERT_EQ(track.samples.size(), 7u);  // s = 0, 2, ..., 12: the whole length is covered
  const Pose2d a = track.samples[2], b = track.samples[3], mid = track.at(5.0);
  EXPECT_DOUBLE_EQ(mid.x, 0.5 * (a.x + b.x));
  EXPECT_DOUBLE_EQ(mid.yaw, 0.5 * (a.yaw + b.yaw));
  EXPECT_DOUBLE_EQ(track.at(-3).x, track.samples.front().x);
  EXPECT_DOUBLE_EQ(track.at(1e9).y, track.samples.back().y);
  c.sigma_xy_m = c.heading_sigma_rad = 0;
  std::mt19937_64 rng0(1);
  for (const Pose2d& e : simulate_survey_error(c, 11.0, rng0).samples) EXPECT_TRUE(e.x == 0 && e.y == 0 && e.yaw == 0);
}

// A long straight two-way road: two 4 m lanes, curbs at y = -4 and +4, lane centres at y = -2 and +2.
constexpr double kRoadLength = 3000.0, kHalfWidth = 4.0, kLaneOffset = 2.0;
const char* kLongRoad = R"(name: long_road
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2}
roads:
  - {name: main, points: [[0, 0], [3000, 0]]}
)";

struct LongRoad {
  WorldDescription description = parse_world_description(kLongRoad, "long_road.yaml");
  World world = build_world(description, test::materials(), test::data_path("assets/actors"));
};
const LongRoad& long_road() {
  static const LongRoad road;
  return road;
}

SurveyDrive survey(const WorldDescription& d, const SurveyErrorConfig& c, uint64_t seed) {
  std::mt19937_64 rng(seed);
  return plan_survey(d, c, rng);
}

// Signed distance from p to the nearest segment of the world's curbs (positive to the left of the
// segment's direction). Segments are bucketed by the metres of x they span: the road runs along x.
class CurbLines {
 public:
  explicit CurbLines(const std::vector<Polyline2d>& lines) {
    for (const auto& line : lines)
      for (size_t i = 1; i < line.size(); ++i) {
        const Eigen::Vector2d a = line[i - 1], b = line[i];
        if ((b - a).norm() == 0) continue;
        for (int x = int(std::floor(std::min(a.x(), b.x()))); x <= int(std::floor(std::max(a.x(), b.x()))); ++x)
          buckets_[x].push_back({a, b});
      }
  }
  double across(const Eigen::Vector2d& p) const {
    double best = std::numeric_limits<double>::infinity(), out = 0;
    for (int x = int(std::floor(p.x())) - 1; x <= int(std::floor(p.x())) + 1; ++x) {
      const auto it = buckets_.find(x);
      if (it == buckets_.end()) continue;
      for (const auto& [a, b] : it->second) {
        const Eigen::Vector2d u = (b - a).normalized(), left(-u.y(), u.x());
        const double t = std::clamp((p - a).dot(u), 0.0, (b - a).norm());
        const double dist = (a + t * u - p).norm();
        if (dist < best) best = dist, out = (p - a).dot(left);
      }
    }
    return out;
  }

 private:
  std::map<int, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>> buckets_;
};

// The surveyed curb points away from the road's ends, with their offsets from the world's lines and
// their shift along the road (x) from the densified world point they came from.
struct CurbErrors {
  std::vector<double> across, along_shift;
};
CurbErrors curb_errors(const SurveyErrorConfig& c, uint64_t seed) {
  const LongRoad& road = long_road();
  const CurbMap world = densify_curb_map(road.world.curb_map(), c.sample_spacing_m);
  const CurbMap surveyed = survey_curb_map(world, survey(road.description, c, seed));
  constexpr double kAwayFromEnds = 50.0;  // m: the ends' curbs run across the road
  const CurbLines lines(road.world.curbs);
  CurbErrors out;
  for (size_t k = 0; k < world.curbs.size(); ++k)
    for (size_t i = 0; i < world.curbs[k].size(); ++i) {
      const Eigen::Vector2d w = world.curbs[k][i], s = surveyed.curbs[k][i];
      if (w.x() < kAwayFromEnds || w.x() > kRoadLength - kAwayFromEnds) continue;
      out.across.push_back(lines.across(s));
      out.along_shift.push_back(s.x() - w.x());
    }
  return out;
}

TEST(SurveyCurbs, CurbLineErrorAgainstTheWorldsCurbsHasTheConfiguredStatistics) {
  ASSERT_NEAR(std::abs(long_road().world.curbs.front().front().y()), kHalfWidth, 1e-6);
  SurveyErrorConfig c;  // the default heading error; a short correlation length for a tight estimate
  c.correlation_length_m = 5.0;
  c.heading_correlation_length_m = 5.0;
  c.sample_spacing_m = 0.1;
  const CurbErrors e = curb_errors(c, 11);
  ASSERT_GT(e.across.size(), size_t(2 * 0.9 * (kRoadLength - 100) / c.sample_spacing_m));
  const Moments m = moments(e.across);
  std::cout << "[ figures  ] curb-line error over " << e.across.size() << " points: mean " << m.mean * 1000
            << " mm, sigma " << m.sigma * 1000 << " mm (configured sigma_xy " << c.sigma_xy_m * 1000 << " mm)\n";
  // Each side's curb follows its own lane's error: about 2 x 2900 m / (2 x 5 m) independent stretches.
  EXPECT_NEAR(m.mean, 0.0, 0.15 * c.sigma_xy_m);  // about 3.5 standard errors
  EXPECT_NEAR(m.sigma, c.sigma_xy_m, 0.2 * c.sigma_xy_m);
  // Not white noise at the vertices: neighbours 0.1 m apart share almost all their error.
  EXPECT_GT(autocorrelation(e.across, 1), 0.9);
}

TEST(SurveyCurbs, HeadingErrorTurnsTheCurbsAboutTheNearestSurveyPose) {
  // No position error, 1 deg of heading error: a curb kLaneOffset to the side of the survey car moves
  // along the road by kLaneOffset * e_yaw, and across it only to second order.
  SurveyErrorConfig c;
  c.sigma_xy_m = 0;
  c.heading_sigma_rad = 1.0 * kDeg;
  c.heading_correlation_length_m = 5.0;
  c.sample_spacing_m = 0.1;
  const CurbErrors e = curb_errors(c, 12);
  const Moments along = moments(e.along_shift);
  const double expected = (kHalfWidth - kLaneOffset) * c.heading_sigma_rad;
  std::cout << "[ figures  ] along-road curb shift sigma " << along.sigma * 1000 << " mm (expected " << expected * 1000
            << " mm)\n";
  EXPECT_NEAR(along.sigma, expected, 0.1 * expected);
  // Across: kLaneOffset (1 - cos e_yaw), about 0.3 mm on average.
  const Moments across = moments(e.across);
  EXPECT_LT(std::abs(across.mean) + across.sigma, 0.05 * expected);
}

TEST(SurveyCurbs, ZeroSurveyErrorGivesBackTheWorldsCurbLinesExactly) {
  // A bent road, so the curbs lie at no round offsets from the survey poses.
  const char* bent = R"(name: bent_road
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 7.5, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2}
roads:
  - {name: main, points: [[0, 0], [130, 47.3], [210, -31.9]], smoothing_radius: 35}
)";
  const WorldDescription d = parse_world_description(bent, "bent_road.yaml");
  const World w = build_world(d, test::materials(), test::data_path("assets/actors"));
  SurveyErrorConfig c;
  c.sigma_xy_m = 0;
  c.heading_sigma_rad = 0;
  const CurbMap world = densify_curb_map(w.curb_map(), 0.37);
  const CurbMap surveyed = survey_curb_map(world, survey(d, c, 5));
  EXPECT_EQ(surveyed.world, world.world);
  EXPECT_EQ(surveyed.origin.lat_deg, world.origin.lat_deg);
  EXPECT_EQ(surveyed.origin.lon_deg, world.origin.lon_deg);
  ASSERT_EQ(surveyed.curbs.size(), world.curbs.size());
  size_t points = 0, moved_points = 0;
  for (size_t k = 0; k < world.curbs.size(); ++k) {
    ASSERT_EQ(surveyed.curbs[k].size(), world.curbs[k].size());
    for (size_t i = 0; i < world.curbs[k].size(); ++i, ++points)
      moved_points +=
          surveyed.curbs[k][i].x() != world.curbs[k][i].x() || surveyed.curbs[k][i].y() != world.curbs[k][i].y();
  }
  EXPECT_GT(points, 1000u);
  EXPECT_EQ(moved_points, 0u) << "of " << points;
  // With the default error every point moves.
  const CurbMap moved = survey_curb_map(world, survey(d, SurveyErrorConfig{}, 5));
  for (size_t k = 0; k < world.curbs.size(); ++k)
    for (size_t i = 0; i < world.curbs[k].size(); ++i) EXPECT_NE(moved.curbs[k][i], world.curbs[k][i]);
}

TEST(SurveyCurbs, DensifyingKeepsEveryVertexAndBoundsTheSpacing) {
  CurbMap map;
  map.world = "w";
  map.curbs = {{{0, 0}, {10, 0}, {10, 0.3}, {10, 7}}, {{5, 5}}};
  const CurbMap dense = densify_curb_map(map, 0.5);
  EXPECT_EQ(dense.world, "w");
  ASSERT_EQ(dense.curbs.size(), 2u);
  EXPECT_EQ(dense.curbs[1], map.curbs[1]);
  const Polyline2d& line = dense.curbs[0];
  EXPECT_EQ(line.size(), 1u + 20 + 1 + 14);
  size_t next = 0;  // the original vertices appear in order
  for (const auto& p : line) {
    if (next < map.curbs[0].size() && p == map.curbs[0][next]) ++next;
  }
  EXPECT_EQ(next, map.curbs[0].size());
  for (size_t i = 1; i < line.size(); ++i) EXPECT_LE((line[i] - line[i - 1]).norm(), 0.5 + 1e-12);
}

// An 80 m two-way road whose only paint is a crosswalk at x = 40.
constexpr double kCrosswalkX = 40.0;
const char* kCrosswalkRoad = R"(name: crosswalk_road
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2}
roads:
  - {name: main, points: [[0, 0], [80, 0]]}
crosswalks:
  - {road: main, at: 40, width: 4.0}
)";

struct CrosswalkRoad {
  WorldDescription description = parse_world_description(kCrosswalkRoad, "crosswalk_road.yaml");
  World world = build_world(description, test::materials(), test::data_path("assets/actors"));
};
const CrosswalkRoad& crosswalk_road() {
  static const CrosswalkRoad road;
  return road;
}

IntensityMapBuilder drive(const MappingOptions& o) {
  const CrosswalkRoad& r = crosswalk_road();
  return run_mapping_drive(r.description, r.world, test::materials(), test::data_path("assets/actors"), o, "test");
}

// The paint's centroid in the intensity layer: cells weighted by how much brighter than the asphalt
// (the window's median cell) they are.
Eigen::Vector2d paint_centroid(const IntensityMapBuilder& map) {
  const double res = map.header().resolution_m;
  constexpr double kHalfX = 4.0, kHalfY = 3.6;  // m: the crosswalk (4 m x 6.3 m) and a margin
  std::vector<std::pair<Eigen::Vector2d, double>> cells;
  for (double x = kCrosswalkX - kHalfX; x < kCrosswalkX + kHalfX; x += res)
    for (double y = -kHalfY; y < kHalfY; y += res) {
      const Eigen::Vector2d c(std::floor(x / res) * res + res / 2, std::floor(y / res) * res + res / 2);
      if (const auto cell = map.cell(c); cell && cell->count > 0) cells.push_back({c, cell->mean});
    }
  std::vector<double> means;
  for (const auto& [c, m] : cells) means.push_back(m);
  std::nth_element(means.begin(), means.begin() + means.size() / 2, means.end());
  const double asphalt = means[means.size() / 2];
  Eigen::Vector2d sum(0, 0);
  double weight = 0;
  for (const auto& [c, m] : cells)
    if (m > asphalt) sum += (m - asphalt) * c, weight += m - asphalt;
  return sum / weight;
}

TEST(MappingDrive, PlacesItsScansWithTheSurveyedPoses) {
  // A survey error that is all but constant over the 160 m drive, and no heading error: the paint
  // must appear shifted by that error.
  MappingOptions exact, shifted;
  exact.survey_error.sigma_xy_m = exact.survey_error.heading_sigma_rad = 0;
  shifted.survey_error.sigma_xy_m = 0.3;
  shifted.survey_error.correlation_length_m = 1e7;
  shifted.survey_error.heading_sigma_rad = 0;
  const SurveyDrive s = mapping_survey(crosswalk_road().description, shifted);
  Eigen::Vector2d expected(0, 0);
  for (const SurveyLane& lane : s.lanes) {
    const Pose2d e = s.error.at(lane.start_m + lane.path.project({kCrosswalkX, 0}));
    expected += Eigen::Vector2d(e.x, e.y) / double(s.lanes.size());
  }
  ASSERT_GT(expected.norm(), 0.1);  // large enough to see (this seed)
  const Eigen::Vector2d moved = paint_centroid(drive(shifted)) - paint_centroid(drive(exact));
  std::cout << "[ figures  ] paint moved by (" << moved.x() << ", " << moved.y() << ") m, survey error ("
            << expected.x() << ", " << expected.y() << ") m\n";
  EXPECT_NEAR(moved.x(), expected.x(), 0.02);
  EXPECT_NEAR(moved.y(), expected.y(), 0.02);
}

std::map<std::string, std::string> folder_bytes(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& f : std::filesystem::recursive_directory_iterator(dir))
    if (f.is_regular_file()) {
      std::ifstream in(f.path(), std::ios::binary);
      std::stringstream s;
      s << in.rdbuf();
      out[std::filesystem::relative(f.path(), dir).string()] = s.str();
    }
  return out;
}

// The map (tiles, header and surveyed curbs) a mapping drive with `seed` writes, as bytes per file.
std::map<std::string, std::string> map_bytes(uint64_t seed, const std::string& name) {
  MappingOptions o;
  o.seed = seed;
  const std::string dir = testing::TempDir() + "/survey_map_" + name;
  std::filesystem::remove_all(dir);
  drive(o).save(dir);
  const CrosswalkRoad& r = crosswalk_road();
  write_curb_map(dir + "/curbs.geojson", surveyed_curbs(r.world, mapping_survey(r.description, o), o));
  return folder_bytes(dir);
}

TEST(MappingDrive, SameSeedSameMapBytesOtherSeedOtherMap) {
  const auto a = map_bytes(1, "a"), b = map_bytes(1, "b"), c = map_bytes(2, "c");
  ASSERT_GT(a.size(), 2u);
  EXPECT_TRUE(a == b) << "the same seed gave different maps";
  ASSERT_EQ(c.count("curbs.geojson"), 1u);
  EXPECT_NE(a.at("curbs.geojson"), c.at("curbs.geojson"));
  EXPECT_FALSE(a == c);
}

// The drive runs in parts on every core and merges them in a fixed order: the map's bytes must not
// depend on the thread count, nor on whether the tiles are written as they are finished (what
// `lidarloop map` does) or kept in memory until the end.
TEST(MappingDrive, SameMapBytesAtOneAndTwoThreadsStreamedOrNot) {
  MappingOptions o;
  const CrosswalkRoad& r = crosswalk_road();
  std::map<std::string, std::string> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = map_bytes(1, "one_thread");
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    const std::string dir = testing::TempDir() + "/survey_map_two_threads_streamed";
    std::filesystem::remove_all(dir);
    IntensityMapWriter writer(dir);
    const IntensityMapHeader header =
        run_mapping_drive(r.description, r.world, test::materials(), test::data_path("assets/actors"), o, "test",
                          [&](const IntensityMapHeader& h, const std::pair<int, int>& key,
                              std::vector<IntensityMoments>& cells) { writer.write_tile(h, key, cells); });
    writer.finish(header);
    write_curb_map(dir + "/curbs.geojson", surveyed_curbs(r.world, mapping_survey(r.description, o), o));
    two = folder_bytes(dir);
  }
  ASSERT_GT(one.size(), 3u);  // header, curbs and tiles
  EXPECT_TRUE(one == two) << "1 thread in memory and 2 threads streamed gave different maps";
}

TEST(MappingOptions, DescribeChangesWithEverySurveySetting) {
  const MappingOptions base;
  std::vector<MappingOptions> changed(7, base);
  changed[0].survey_error.sigma_xy_m += 1e-9;
  changed[1].survey_error.correlation_length_m += 1e-9;
  changed[2].survey_error.heading_sigma_rad += 1e-12;
  changed[3].survey_error.heading_correlation_length_m += 1e-9;
  changed[4].survey_error.sample_spacing_m += 1e-9;
  changed[5].survey_unit_serial += 1;
  changed[6].seed += 1;
  for (size_t i = 0; i < changed.size(); ++i) EXPECT_NE(changed[i].describe(), base.describe()) << "setting " << i;
  EXPECT_NE(base.survey_unit_serial, Hdl32eConfig{}.unit_serial) << "the survey must use another sensor unit";
}

TEST(MappingOptions, SurveySettingsReadFromYaml) {
  const YamlReader yaml = YamlReader::from_string(
      "{unit_serial: 7, sigma_xy_m: 0.05, correlation_length_m: 30, heading_sigma_deg: 0.1,\n"
      " heading_correlation_length_m: 40, sample_spacing_m: 0.25}",
      "survey.yaml");
  MappingOptions o;
  read_survey_options(yaml, yaml.root(), o);
  EXPECT_EQ(o.survey_unit_serial, 7u);
  EXPECT_EQ(o.survey_error.sigma_xy_m, 0.05);
  EXPECT_EQ(o.survey_error.correlation_length_m, 30);
  EXPECT_NEAR(o.survey_error.heading_sigma_rad, 0.1 * kDeg, 1e-15);
  EXPECT_EQ(o.survey_error.heading_correlation_length_m, 40);
  EXPECT_EQ(o.survey_error.sample_spacing_m, 0.25);
  const YamlReader typo = YamlReader::from_string("{sigma_xy: 0.05}", "typo.yaml");
  EXPECT_THROW(read_survey_options(typo, typo.root(), o), InputError);
}

}  // namespace
}  // namespace lidarloop
