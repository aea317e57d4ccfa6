// The map's provenance: a GNSS-anchored SLAM map's error field recovers its configured absolute and
// relative figures and belongs to the place (every pass of a street shares it), and the settings read
// from YAML key the map cache while the default survey keeps the key it always had.
#include <cmath>
#include <iostream>
#include <numbers>

#include <gtest/gtest.h>

#include "mapping/mapping_drive.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

struct FieldFigures {
  double absolute_rms = 0, relative_rms = 0, rotation_rms = 0, mean_east = 0, mean_north = 0;
};

// The field's figures along straight tracks of `length` m in several directions, over `seeds` draws:
// the horizontal RMS of the error, of its change over `over` m, and of its rotation.
FieldFigures measure(const SlamMapErrorConfig& c, double over, int seeds, double length) {
  constexpr double kStep = 1.0;  // m: far below the correlation length
  double sum2 = 0, rel2 = 0, rot2 = 0, east = 0, north = 0;
  size_t n = 0, n_rel = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    std::mt19937_64 rng{uint64_t(seed)};
    const SlamErrorField field(c, rng);
    const double angle = seed * 0.7;  // a track in another direction for each draw
    const Eigen::Vector2d u(std::cos(angle), std::sin(angle)), start(seed * 1000.0, -seed * 500.0);
    const int steps = int(length / kStep), lag = int(std::lround(over / kStep));
    std::vector<Pose2d> e;
    for (int i = 0; i <= steps; ++i) e.push_back(field.at(start + u * (i * kStep)));
    for (size_t i = 0; i < e.size(); ++i) {
      sum2 += e[i].x * e[i].x + e[i].y * e[i].y;
      rot2 += e[i].yaw * e[i].yaw;
      east += e[i].x, north += e[i].y;
      ++n;
      if (i + size_t(lag) < e.size()) {
        const double dx = e[i + size_t(lag)].x - e[i].x, dy = e[i + size_t(lag)].y - e[i].y;
        rel2 += dx * dx + dy * dy;
        ++n_rel;
      }
    }
  }
  return {std::sqrt(sum2 / double(n)), std::sqrt(rel2 / double(n_rel)), std::sqrt(rot2 / double(n)), east / double(n),
          north / double(n)};
}

TEST(SlamMapError, AbsoluteAndRelativeErrorsRecoverTheConfiguredFigures) {
  SlamMapErrorConfig other;  // a second set of figures, so the test follows the configuration
  other.absolute_sigma_m = 0.10;
  other.relative_sigma_m = 0.05;
  other.relative_over_m = 30.0;
  for (const SlamMapErrorConfig& c : {SlamMapErrorConfig{}, other}) {
    const double length = slam_correlation_length(c);
    constexpr int kSeeds = 8;
    const FieldFigures f = measure(c, c.relative_over_m, kSeeds, 200 * length);
    const double rotation = c.absolute_sigma_m / (2 * length);
    std::cout << "[ figures  ] slam map error (l = " << length << " m): absolute RMS " << f.absolute_rms * 100
              << " cm (configured " << c.absolute_sigma_m * 100 << "), relative over " << c.relative_over_m << " m "
              << f.relative_rms * 100 << " cm (configured " << c.relative_sigma_m * 100 << "), rotation "
              << f.rotation_rms / kDeg << " deg (expected " << rotation / kDeg << ")\n";
    EXPECT_NEAR(f.absolute_rms, c.absolute_sigma_m, 0.05 * c.absolute_sigma_m);
    EXPECT_NEAR(f.relative_rms, c.relative_sigma_m, 0.06 * c.relative_sigma_m);
    EXPECT_NEAR(f.rotation_rms, rotation, 0.08 * rotation);
    EXPECT_NEAR(f.mean_east, 0.0, 0.1 * c.absolute_sigma_m);
    EXPECT_NEAR(f.mean_north, 0.0, 0.1 * c.absolute_sigma_m);
  }
}

TEST(SlamMapError, RelativeErrorGrowsWithDistanceAndSaturatesAtTheAnchorsBound) {
  // Over 5 m the error changes a quarter of its 20 m change (it grows in proportion to the distance);
  // over 20 correlation lengths the two places are independent: sqrt(2) times the absolute error.
  const SlamMapErrorConfig c;
  const double length = slam_correlation_length(c);
  const FieldFigures near = measure(c, 5.0, 8, 200 * length);
  const FieldFigures far = measure(c, 20 * length, 8, 200 * length);
  EXPECT_NEAR(near.relative_rms, 0.25 * c.relative_sigma_m, 0.06 * 0.25 * c.relative_sigma_m);
  EXPECT_NEAR(far.relative_rms, std::sqrt(2.0) * c.absolute_sigma_m, 0.08 * std::sqrt(2.0) * c.absolute_sigma_m);
}

TEST(SlamMapError, ImpossibleFiguresAreRefused) {
  SlamMapErrorConfig c;
  c.relative_sigma_m = 1.5 * c.absolute_sigma_m;  // above sqrt(2) times the absolute error
  EXPECT_THROW(slam_correlation_length(c), std::invalid_argument);
  c = {};
  c.absolute_sigma_m = 0;
  EXPECT_THROW(slam_correlation_length(c), std::invalid_argument);
}

// A long straight two-way road: the survey drives its right lane forward (y = -2) and back (y = +2).
const char* kLongRoad = R"(name: long_road
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: none, edge_lines: false, sidewalk_width: 2}
roads:
  - {name: main, points: [[0, 0], [3000, 0]]}
)";

TEST(SlamMapError, BothPassesOfAStreetShareItsErrorWhereTheRtkSurveysDoNot) {
  const WorldDescription d = parse_world_description(kLongRoad, "long_road.yaml");
  // The error of the forward pass at x against the backward pass's at the same x, 4 m across.
  auto pass_difference = [&](const SurveyErrorConfig& c) {
    std::mt19937_64 rng(9);
    const SurveyDrive drive = plan_survey(d, c, rng);
    EXPECT_EQ(drive.lanes.size(), 2u);
    const double length = drive.lanes[0].path.length;
    double sum2 = 0;
    int n = 0;
    for (double x = 50; x < length - 50; x += 1.0, ++n) {
      const Pose2d forward = drive.error.at(x), backward = drive.error.at(drive.lanes[1].start_m + (length - x));
      sum2 += std::pow(forward.x - backward.x, 2) + std::pow(forward.y - backward.y, 2);
    }
    return std::sqrt(sum2 / n);
  };
  SurveyErrorConfig slam;
  slam.provenance = MapProvenance::slam;
  const double l = slam_correlation_length(slam.slam);
  // The field's change over the 4 m between the lanes.
  const double expected = slam.slam.absolute_sigma_m * std::sqrt(2 * (1 - std::exp(-16.0 / (2 * l * l))));
  const double slam_difference = pass_difference(slam), rtk_difference = pass_difference(SurveyErrorConfig{});
  std::cout << "[ figures  ] the two passes' error differs by " << slam_difference * 100
            << " cm RMS under slam (expected " << expected * 100 << "), " << rtk_difference * 100
            << " cm under rtk_ins\n";
  EXPECT_LT(slam_difference, 2 * expected);
  // Two independent Gauss-Markov errors of 2 cm per axis: 4 cm apart RMS.
  EXPECT_GT(rtk_difference, 0.6 * 2 * SurveyErrorConfig{}.sigma_xy_m);
}

TEST(MapProvenance, TheDefaultSurveyKeepsItsCacheKey) {
  // The text every cached typical map was keyed by before there were provenances and conventions (and
  // before typical's paint was worn: uniform paint adds nothing to it).
  MappingOptions uniform;
  uniform.paint.varied = false;
  EXPECT_EQ(uniform.describe(),
            "traffic=0 speed=15 resolution=0.2 tile_cells=320 max_ground_height=0.5 max_range=40 seed=1 "
            "survey_unit_serial=2 sigma_xy_m=0.02 correlation_length_m=100 heading_sigma_deg=0.05 "
            "heading_correlation_length_m=100 sample_spacing_m=0.5 point_voxel=0.4 point_scan_stride=4");
  EXPECT_EQ(mapping_options_for(Realism::typical).describe(), MappingOptions{}.describe());
}

TEST(MapProvenance, ProvenanceAndLabellingReadFromYamlAndKeyTheCache) {
  const YamlReader yaml = YamlReader::from_string(
      "{provenance: slam, slam_absolute_m: 0.2, slam_relative_m: 0.04, slam_relative_over_m: 25,\n"
      " curb_label: gutter_line, label_noise_m: 0.02, label_noise_correlation_m: 3}",
      "survey.yaml");
  MappingOptions o;
  read_survey_options(yaml, yaml.root(), o);
  EXPECT_EQ(o.survey_error.provenance, MapProvenance::slam);
  EXPECT_EQ(o.survey_error.slam.absolute_sigma_m, 0.2);
  EXPECT_EQ(o.survey_error.slam.relative_sigma_m, 0.04);
  EXPECT_EQ(o.survey_error.slam.relative_over_m, 25);
  EXPECT_EQ(o.curb_label.convention, CurbLabel::gutter_line);
  EXPECT_EQ(o.curb_label.noise_m, 0.02);
  EXPECT_EQ(o.curb_label.noise_correlation_m, 3);
  // Each new setting changes the cache key.
  std::vector<MappingOptions> changed(6, MappingOptions{});
  changed[0].survey_error.provenance = MapProvenance::slam;
  changed[1] = changed[0], changed[1].survey_error.slam.absolute_sigma_m += 1e-9;
  changed[2] = changed[0], changed[2].survey_error.slam.relative_sigma_m += 1e-9;
  changed[3] = changed[0], changed[3].survey_error.slam.relative_over_m += 1e-9;
  changed[4].curb_label.convention = CurbLabel::face_top;
  changed[5].curb_label.noise_m = 1e-9;
  for (size_t i = 0; i < changed.size(); ++i) {
    EXPECT_NE(changed[i].describe(), MappingOptions{}.describe()) << "setting " << i;
    for (size_t j = 0; j < i; ++j) EXPECT_NE(changed[i].describe(), changed[j].describe()) << i << " " << j;
  }
}

// The error a survey YAML gives, or "" when it reads.
std::string survey_error_text(const std::string& text) {
  const YamlReader yaml = YamlReader::from_string(text, "scenario.yaml");
  MappingOptions o;
  try {
    read_survey_options(yaml, yaml.root(), o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MapProvenance, MistakesAreErrorsNamingTheFileAndTheKey) {
  EXPECT_EQ(survey_error_text("{provenance: rtk_ins, curb_label: face_foot}"), "");
  const std::string unknown = survey_error_text("{provenance: slam, curb_labels: face_top}");
  EXPECT_NE(unknown.find("scenario.yaml"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("curb_labels"), std::string::npos) << unknown;
  EXPECT_NE(survey_error_text("{provenance: lidar_slam}").find("rtk_ins or slam"), std::string::npos);
  EXPECT_NE(survey_error_text("{curb_label: kerb}").find("face_foot, face_top or gutter_line"), std::string::npos);
  // A figure of the other provenance's model would be silently unused.
  EXPECT_NE(survey_error_text("{provenance: slam, sigma_xy_m: 0.1}").find("sigma_xy_m"), std::string::npos);
  EXPECT_NE(survey_error_text("{slam_absolute_m: 0.1}").find("slam_absolute_m"), std::string::npos);
  EXPECT_NE(survey_error_text("{provenance: slam, slam_relative_m: 0.5}").find("sqrt(2)"), std::string::npos);
}

}  // namespace
}  // namespace lidarloop
