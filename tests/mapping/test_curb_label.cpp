// The curb layer as a labeller draws it: each convention's line lies where the curb's cross-section
// puts it (measured against the world's roads, whose curbs run straight along x), and the labelling
// noise has the configured RMS and correlation along the line.
#include <cmath>
#include <iostream>
#include <map>

#include <gtest/gtest.h>

#include "mapping/mapping_drive.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// Four straight roads 200 m long along x, 50 m apart, one per curb profile, 15 cm curbs; the fourth a
// vertical curb behind a 0.6 m gutter pan.
constexpr double kLength = 200.0, kSpacing = 50.0, kCurbHeight = 0.15, kGutter = 0.6;
const char* kProfiles = R"(name: profiles
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 7.0, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2, curb_height: 0.15}
roads:
  - {name: vertical, points: [[0, 0], [200, 0]]}
  - {name: sloped, points: [[0, 50], [200, 50]], curb_profile: sloped}
  - {name: rolled, points: [[0, 100], [200, 100]], curb_profile: rolled}
  - {name: guttered, points: [[0, 150], [200, 150]], gutter_width: 0.6}
)";

struct ProfilesWorld {
  WorldDescription description = parse_world_description(kProfiles, "profiles.yaml");
  World world = build_world(description, test::materials(), test::data_path("assets/actors"));
};
const ProfilesWorld& profiles_world() {
  static const ProfilesWorld w;
  return w;
}

// Per road (by its index, from y), the labelled points' offsets from the world's points, positive away
// from the road's centreline; points within 20 m of a road's ends are left out (the curbs there turn
// across the road's end).
std::map<int, std::vector<double>> offsets_by_road(const CurbMap& world, const CurbMap& labelled) {
  constexpr double kAwayFromEnds = 20.0;
  std::map<int, std::vector<double>> out;
  for (size_t k = 0; k < world.curbs.size(); ++k)
    for (size_t i = 0; i < world.curbs[k].size(); ++i) {
      const Eigen::Vector2d w = world.curbs[k][i], l = labelled.curbs[k][i];
      if (w.x() < kAwayFromEnds || w.x() > kLength - kAwayFromEnds) continue;
      const int road = int(std::lround(w.y() / kSpacing));
      const double outward = w.y() > road * kSpacing ? 1.0 : -1.0;
      out[road].push_back((l - w).y() * outward);
      EXPECT_NEAR(l.x(), w.x(), 1e-9) << "a straight curb's point moves across it only";
    }
  return out;
}

TEST(CurbLabel, EachConventionsOffsetOnEachProfileIsTheGeometrys) {
  const ProfilesWorld& w = profiles_world();
  const CurbMap world = densify_curb_map(w.world.curb_map(), 0.5);
  // Expected offsets from the cross-sections the world is built with (sim/curb_band.cpp): a sloped face
  // is a 1:1 batter (run = height), a rolled one runs twice its height, a gutter pan lies in front of
  // the face's foot, which is the world's curb line.
  const std::map<CurbLabel, std::vector<double>> expected = {
      {CurbLabel::face_foot, {0, 0, 0, 0}},
      {CurbLabel::face_top, {0, kCurbHeight, 2 * kCurbHeight, 0}},
      {CurbLabel::gutter_line, {0, 0, 0, -kGutter}},
  };
  for (const auto& [label, offsets] : expected) {
    CurbLabelConfig c;
    c.convention = label;
    std::mt19937_64 rng(1);
    const auto by_road = offsets_by_road(world, label_curb_map(world, w.world.curb_band->rings(), c, rng));
    ASSERT_EQ(by_road.size(), 4u);
    for (const auto& [road, values] : by_road) {
      ASSERT_GT(values.size(), size_t(2 * (kLength - 40) / 0.5 * 0.9)) << "road " << road;
      for (double v : values)
        ASSERT_NEAR(v, offsets[size_t(road)], 1e-6) << curb_label_name(label) << " on road " << road;
    }
    std::cout << "[ figures  ] " << curb_label_name(label) << ": offsets vertical " << offsets[0] << ", sloped "
              << offsets[1] << ", rolled " << offsets[2] << ", guttered " << offsets[3] << " m, as measured\n";
  }
}

TEST(CurbLabel, LabelNoiseHasTheConfiguredRmsAndCorrelationAlongTheLine) {
  const char* long_road = R"(name: long_road
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2}
roads:
  - {name: main, points: [[0, 0], [3000, 0]]}
)";
  const WorldDescription d = parse_world_description(long_road, "long_road.yaml");
  const World w = build_world(d, test::materials(), test::data_path("assets/actors"));
  constexpr double kStep = 0.5;
  const CurbMap world = densify_curb_map(w.curb_map(), kStep);
  CurbLabelConfig c;
  c.noise_m = 0.04;
  c.noise_correlation_m = 5.0;
  std::mt19937_64 rng(4);
  const CurbMap labelled = label_curb_map(world, w.curb_band->rings(), c, rng);
  // Along each curb in order, away from the ends: the offset and the place.
  std::vector<std::vector<std::pair<double, Eigen::Vector2d>>> runs;
  for (size_t k = 0; k < world.curbs.size(); ++k) {
    runs.emplace_back();
    for (size_t i = 0; i < world.curbs[k].size(); ++i) {
      const Eigen::Vector2d p = world.curbs[k][i];
      if (p.x() < 20 || p.x() > 2980 || std::abs(std::abs(p.y()) - 4.0) > 1e-6) continue;
      runs.back().push_back({(labelled.curbs[k][i] - p).y() * (p.y() > 0 ? 1 : -1), p});
    }
  }
  // Densified vertices lie at most kStep apart, not exactly: the expected correlation of each pair is
  // exp(-its distance / L), averaged over the pairs used.
  double sum = 0, sum2 = 0, lagged = 0, expected_correlation = 0;
  size_t n = 0, n_lagged = 0;
  const size_t lag = size_t(std::lround(c.noise_correlation_m / kStep));
  for (const auto& run : runs)
    for (size_t i = 0; i < run.size(); ++i) {
      sum += run[i].first, sum2 += run[i].first * run[i].first, ++n;
      if (i + lag < run.size()) {
        lagged += run[i].first * run[i + lag].first, ++n_lagged;
        expected_correlation += std::exp(-(run[i + lag].second - run[i].second).norm() / c.noise_correlation_m);
      }
    }
  expected_correlation /= double(n_lagged);
  ASSERT_GT(n, 10000u);
  const double rms = std::sqrt(sum2 / double(n)), mean = sum / double(n);
  const double correlation = lagged / double(n_lagged) / (rms * rms);
  std::cout << "[ figures  ] label noise over " << n << " points: RMS " << rms * 1000 << " mm (configured "
            << c.noise_m * 1000 << "), mean " << mean * 1000 << " mm, correlation at " << c.noise_correlation_m << " m "
            << correlation << " (expected " << std::exp(-1.0) << ")\n";
  // About 2 x 2960 m / 5 m = 1200 correlation lengths: the RMS to about 2 %.
  EXPECT_NEAR(rms, c.noise_m, 0.06 * c.noise_m);
  EXPECT_NEAR(mean, 0.0, 0.1 * c.noise_m);
  EXPECT_NEAR(correlation, expected_correlation, 0.06);
}

TEST(CurbLabel, TheDefaultConventionGivesBackTheWorldsLinesWithoutDrawing) {
  const ProfilesWorld& w = profiles_world();
  const CurbMap world = densify_curb_map(w.world.curb_map(), 0.5);
  std::mt19937_64 rng(7), untouched(7);
  const CurbMap labelled = label_curb_map(world, w.world.curb_band->rings(), CurbLabelConfig{}, rng);
  ASSERT_EQ(labelled.curbs.size(), world.curbs.size());
  for (size_t k = 0; k < world.curbs.size(); ++k) EXPECT_EQ(labelled.curbs[k], world.curbs[k]);
  EXPECT_EQ(labelled.kinds, world.kinds);
  EXPECT_EQ(rng(), untouched());
  // And the map's surveyed curbs are today's: the world's, moved by the survey error only.
  const MappingOptions o;
  const SurveyDrive survey = mapping_survey(w.description, o);
  const CurbMap expected = survey_curb_map(world, survey), got = surveyed_curbs(w.world, survey, o);
  for (size_t k = 0; k < world.curbs.size(); ++k) EXPECT_EQ(got.curbs[k], expected.curbs[k]);
}

}  // namespace
}  // namespace lidarloop
