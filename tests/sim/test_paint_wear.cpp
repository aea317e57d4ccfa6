// Worn paint (sim/paint_wear.hpp): the drawn retroreflectivity spread, the worn share of the paint, the
// LiDAR reflectivity's R^2 against the retroreflectivity, the survey-to-drive changes, determinism, the
// profiles and the scenario keys. Each test recovers a configured figure from many markings.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/mesh_shapes.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/paint_wear.hpp"
#include "sim/scenario.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr int kMarkings = 20000;

// Worn paint with the sourced campus figures (the config's defaults, with varied on).
PaintConfig worn() {
  PaintConfig c;
  c.varied = true;
  return c;
}
constexpr double kLanePaint = 0.65;  // lane_paint's reflectivity (assets/materials.yaml)

std::vector<MarkingLook> draw(const PaintConfig& c, PaintDay day, int n = kMarkings, double material = kLanePaint) {
  const PaintRng rng(c.seed);
  std::vector<MarkingLook> out;
  for (int i = 0; i < n; ++i) out.push_back(draw_marking(c, day, rng, material, marking_key({0.5 * i, 0.0})));
  return out;
}

double mean_of(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()); }
double sigma_of(const std::vector<double>& v) {
  const double m = mean_of(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size() - 1));
}
std::vector<double> retro_of(const std::vector<MarkingLook>& looks) {
  std::vector<double> r;
  for (const auto& l : looks) r.push_back(l.retro_mcd);
  return r;
}
// R^2 of the least-squares line of y on x: the squared correlation.
double r_squared(const std::vector<double>& x, const std::vector<double>& y) {
  const double mx = mean_of(x), my = mean_of(y);
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
  return sxy * sxy / (sxx * syy);
}

TEST(PaintWear, TheDrawnRetroreflectivityHasTheConfiguredMeanSigmaAndFloor) {
  const PaintConfig typical;
  const std::vector<double> r = retro_of(draw(typical, PaintDay::survey));
  // The measured figures, for a report (--gtest_output=xml).
  RecordProperty("retro_mean", std::to_string(mean_of(r)));
  RecordProperty("retro_sigma", std::to_string(sigma_of(r)));
  // The floor clamps the 2.3 % of draws 2 sigma below the mean: the mean moves up by about 0.4 mcd and
  // the sigma shrinks by about 3 %.
  EXPECT_NEAR(mean_of(r), typical.retro_mean_mcd, 2.0);
  EXPECT_NEAR(sigma_of(r), typical.retro_sigma_mcd, 0.05 * typical.retro_sigma_mcd);
  EXPECT_EQ(*std::min_element(r.begin(), r.end()), typical.retro_min_mcd);
  const double floored = double(std::count(r.begin(), r.end(), typical.retro_min_mcd)) / double(r.size());
  EXPECT_NEAR(floored, 0.023, 0.006);

  // Another spread, away from the floor: recovered as configured.
  PaintConfig other;
  other.retro_mean_mcd = 320, other.retro_sigma_mcd = 20, other.retro_min_mcd = 0;
  const std::vector<double> r2 = retro_of(draw(other, PaintDay::survey));
  EXPECT_NEAR(mean_of(r2), 320, 0.5);
  EXPECT_NEAR(sigma_of(r2), 20, 0.5);
}

TEST(PaintWear, LidarReflectivityFollowsRetroreflectivityWithTheConfiguredRSquared) {
  // A dim paint (0.3), so that no reflectivity is clamped to 0..1 and no draw floored: the relation alone.
  constexpr double kDim = 0.3;
  for (double wanted : {0.6, 0.75, 0.9}) {
    PaintConfig c;
    c.intensity_r2 = wanted;
    c.retro_min_mcd = 0;
    const auto looks = draw(c, PaintDay::survey, kMarkings, kDim);
    std::vector<double> x, y;
    for (const auto& l : looks) x.push_back(l.retro_mcd), y.push_back(l.reflectivity);
    EXPECT_NEAR(r_squared(x, y), wanted, 0.02) << "configured R^2 " << wanted;
    RecordProperty("r2_for_" + std::to_string(wanted), std::to_string(r_squared(x, y)));
    // On average a marking as bright as material_retro_mcd is its material.
    EXPECT_NEAR(mean_of(y), kDim * c.retro_mean_mcd / c.material_retro_mcd, 0.003);
  }
  // The campus figures (varied: true) with their floor and the clamp to 1: still within the studies' range.
  const auto looks = draw(PaintConfig{}, PaintDay::survey);
  std::vector<double> x, y;
  for (const auto& l : looks) x.push_back(l.retro_mcd), y.push_back(l.reflectivity);
  EXPECT_NEAR(r_squared(x, y), PaintConfig{}.intensity_r2, 0.03);
  RecordProperty("r2_typical", std::to_string(r_squared(x, y)));
}

TEST(PaintWear, TheWornShareOfPiecesIsTheConfiguredFraction) {
  for (double wanted : {0.1, 0.3}) {
    PaintConfig c;
    c.worn_fraction = wanted;
    const PaintRng rng(c.seed);
    int worn = 0;
    for (int i = 0; i < kMarkings; ++i) worn += worn_piece(c, rng, marking_key({0.5 * i, 3.0}));
    EXPECT_NEAR(double(worn) / kMarkings, wanted, 0.01);
  }
}

TEST(PaintWear, TheDriveDayHasTheConfiguredShareOfFadedAndRepaintedMarkings) {
  const PaintConfig c;
  const auto survey = draw(c, PaintDay::survey), drive = draw(c, PaintDay::drive);
  int faded = 0, repainted = 0, same = 0;
  for (size_t i = 0; i < survey.size(); ++i) {
    if (drive[i].repainted) {
      ++repainted;
      EXPECT_EQ(drive[i].retro_mcd, c.repaint_mcd);
    } else if (drive[i].retro_mcd == survey[i].retro_mcd) {
      ++same;
    } else {
      ++faded;
      EXPECT_DOUBLE_EQ(drive[i].retro_mcd, c.fade_factor * survey[i].retro_mcd);
    }
    EXPECT_FALSE(survey[i].repainted);
  }
  EXPECT_NEAR(double(faded) / kMarkings, c.faded_fraction, 0.01);
  EXPECT_NEAR(double(repainted) / kMarkings, c.repainted_fraction, 0.008);
  EXPECT_EQ(faded + repainted + same, kMarkings);
}

TEST(PaintWear, SameSeedSameDrawsOtherSeedOtherDraws) {
  PaintConfig a, b;
  b.seed = 2;
  const auto x = draw(a, PaintDay::drive, 100), y = draw(a, PaintDay::drive, 100), z = draw(b, PaintDay::drive, 100);
  int differ = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].retro_mcd, y[i].retro_mcd);
    EXPECT_EQ(x[i].reflectivity, y[i].reflectivity);
    differ += x[i].retro_mcd != z[i].retro_mcd;
  }
  EXPECT_GT(differ, 90);
}

// A straight road with dashed lane lines, edge lines and a crosswalk: hundreds of markings.
const std::string kRoad = R"(name: painted
origin: {lat: 31.0, lon: 121.0}
geometry: {roughness_class: none, sidewalk_cross_slope: 0}
road_defaults: {cross_slope: 0}
roads:
  - {name: main, points: [[0, 0], [600, 0]], width: 12.0, lanes: 3, marking: dashed, edge_lines: true}
crosswalks:
  - {road: main, near: [300, 0]}
)";

World build(const std::optional<PaintConditions>& paint) {
  WorldDescription d = parse_world_description(kRoad, "painted.yaml");
  d.paint = paint;
  return build_world(d, test::materials(), test::data_path("assets/actors"));
}

// Paint area in the mesh: triangles of a material named as a paint, variants included.
double paint_area(const World& w) {
  const MaterialTable& table = test::materials();
  double area = 0;
  for (size_t t = 0; t < w.mesh.triangles.size(); ++t) {
    const MaterialId m = w.mesh.materials[t];
    const std::string& name = m < table.size() ? table[m].name : w.paint_materials[m - table.size()].name;
    if (name != "lane_paint" && name != "crosswalk_paint") continue;
    const auto& tri = w.mesh.triangles[t];
    const Eigen::Vector3f a = w.mesh.vertices[tri[0]], b = w.mesh.vertices[tri[1]], c = w.mesh.vertices[tri[2]];
    area += 0.5 * double((b - a).cross(c - a).norm());
  }
  return area;
}

bool same_mesh(const World& a, const World& b) {
  const auto bytes_equal = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  return bytes_equal(a.mesh.vertices, b.mesh.vertices) && bytes_equal(a.mesh.triangles, b.mesh.triangles) &&
         bytes_equal(a.mesh.materials, b.mesh.materials);
}

TEST(PaintWear, AWorldLosesTheWornShareOfItsPaintArea) {
  const double uniform = paint_area(build(std::nullopt));
  ASSERT_GT(uniform, 200.0);  // m2: 600 m of lines and a crosswalk
  const PaintConfig c = worn();
  const double left = paint_area(build(PaintConditions{c, PaintDay::survey}));
  EXPECT_NEAR(1 - left / uniform, c.worn_fraction, 0.02);
  RecordProperty("worn_area_fraction", std::to_string(1 - left / uniform));
}

TEST(PaintWear, UniformPaintBuildsTheWorldAsBefore) {
  const World before = build(std::nullopt);
  PaintConfig off;
  off.varied = false;
  for (const PaintConfig& c : {paint_config_for(Realism::ideal), off}) {
    const World uniform = build(PaintConditions{c, PaintDay::drive});
    EXPECT_TRUE(same_mesh(before, uniform));
    EXPECT_TRUE(uniform.paint_materials.empty());
  }
  EXPECT_FALSE(same_mesh(before, build(PaintConditions{paint_config_for(Realism::typical), PaintDay::drive})));
}

TEST(PaintWear, TheSameSeedBuildsTheSameWorldByteForByte) {
  const PaintConditions p{worn(), PaintDay::drive};
  const World a = build(p), b = build(p);
  EXPECT_TRUE(same_mesh(a, b));
  ASSERT_EQ(a.paint_materials.size(), b.paint_materials.size());
  for (size_t i = 0; i < a.paint_materials.size(); ++i)
    EXPECT_EQ(a.paint_materials[i].reflectivity, b.paint_materials[i].reflectivity);
  EXPECT_GT(a.paint_materials.size(), 20u);  // the markings do differ
  PaintConditions other = p;
  other.config.seed = 2;
  EXPECT_FALSE(same_mesh(a, build(other)));
}

TEST(PaintWear, TheSurveyAndTheDriveAgreeOnEveryMarkingNotChanged) {
  const PaintConfig c = worn();
  const World survey = build(PaintConditions{c, PaintDay::survey});
  const World drive = build(PaintConditions{c, PaintDay::drive});
  // The same pieces with the same reflectivity where nothing changed; another material where a marking
  // faded or was re-painted, and the worn pieces of a re-painted one back.
  const MaterialTable& table = test::materials();
  auto pieces = [&](const World& w) {
    std::map<std::array<uint32_t, 3>, double> out;
    for (size_t t = 0; t < w.mesh.triangles.size(); ++t) {
      const MaterialId m = w.mesh.materials[t];
      if (m < table.size()) continue;  // not a marking's own paint
      out[w.mesh.triangles[t]] = w.paint_materials[m - table.size()].reflectivity;
    }
    return out;
  };
  // Worn pieces keep their vertices, so the two meshes share every vertex and triangle index.
  ASSERT_TRUE(survey.mesh.vertices == drive.mesh.vertices);
  const auto before = pieces(survey), after = pieces(drive);
  size_t equal = 0, gone = 0;
  for (const auto& [tri, r] : before) {
    const auto it = after.find(tri);
    if (it == after.end())
      ++gone;
    else
      equal += it->second == r;
  }
  EXPECT_EQ(gone, 0u);  // a marking never loses paint between the days: it fades or is re-painted
  const double changed = 1 - double(equal) / double(before.size());
  RecordProperty("changed_piece_fraction", std::to_string(changed));
  // About the share of markings changed (by area, so roughly): faded and re-painted, 15 %.
  EXPECT_GT(changed, 0.5 * (c.faded_fraction + c.repainted_fraction));
  EXPECT_LT(changed, 2.0 * (c.faded_fraction + c.repainted_fraction));
  EXPECT_GT(after.size(), before.size());  // the re-painted markings' worn pieces are paint again
}

// Worlds imported from a Lanelet2 or an OpenDRIVE map wear their paint the same way.
TEST(PaintWear, ImportedWorldsWearTheirPaintToo) {
  for (const std::string file : {"tests/data/lanelet2/two_lanes.osm", "tests/data/opendrive/small_town.xodr"}) {
    const bool osm = file.ends_with(".osm");
    WorldDescription d =
        osm ? lanelet2_world_description(test::data_path(file)) : opendrive_world_description(test::data_path(file));
    const World before = build_world(d, test::materials(), test::data_path("assets/actors"));
    d.paint = PaintConditions{paint_config_for(Realism::ideal), PaintDay::drive};
    EXPECT_TRUE(same_mesh(before, build_world(d, test::materials(), test::data_path("assets/actors")))) << file;
    d.paint = PaintConditions{worn(), PaintDay::drive};
    const World after = build_world(d, test::materials(), test::data_path("assets/actors"));
    EXPECT_GT(after.paint_materials.size(), 3u) << file;
    const double share = 1 - paint_area(after) / paint_area(before);
    EXPECT_GT(share, 0.03) << file;  // the worn share, less the re-painted markings' (and crosswalks')
    EXPECT_LT(share, 0.2) << file;
    RecordProperty(osm ? "lanelet2_worn_area_fraction" : "opendrive_worn_area_fraction", std::to_string(share));
  }
}

TEST(PaintWear, TheProfilesAndTheScenarioKeys) {
  EXPECT_FALSE(paint_config_for(Realism::ideal).varied);
  EXPECT_TRUE(paint_config_for(Realism::typical).varied);
  EXPECT_EQ(paint_config_for(Realism::typical).retro_mean_mcd, 162.5);  // the campus figures
  EXPECT_TRUE(paint_config_for(Realism::harsh).varied);
  EXPECT_LT(paint_config_for(Realism::harsh).retro_mean_mcd, PaintConfig{}.retro_mean_mcd);
  // Uniform paint adds nothing to a map's cache key: the maps made before this knob keep theirs.
  EXPECT_EQ(paint_config_for(Realism::ideal).describe_survey(), "");
  EXPECT_NE(paint_config_for(Realism::typical).describe_survey(), "");
  // The drive day's changes do not change what the survey saw (the map's cache key).
  PaintConfig changed = worn();
  changed.faded_fraction = 0.4;
  EXPECT_EQ(changed.describe_survey(), worn().describe_survey());
  changed.worn_fraction = 0.2;
  EXPECT_NE(changed.describe_survey(), worn().describe_survey());

  const std::string base = "world: campus\nduration_s: 5\nego: {route: {road: loop}}\n";
  const Scenario s = parse_scenario(base + "paint: {varied: true, worn_fraction: 0.25, seed: 9}\n", "paint.yaml");
  EXPECT_TRUE(s.paint.varied);
  EXPECT_EQ(s.paint.worn_fraction, 0.25);
  EXPECT_EQ(s.paint.seed, 9u);
  EXPECT_FALSE(parse_scenario(base + "realism: ideal\n", "ideal.yaml").paint.varied);
  EXPECT_FALSE(parse_scenario(base + "paint: {varied: false}\n", "uniform.yaml").paint.varied);
  try {
    parse_scenario(base + "paint: {worn_fractoin: 0.25}\n", "typo.yaml");
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("typo.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("worn_fractoin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scenario(base + "paint: {faded_fraction: 0.8, repainted_fraction: 0.3}\n", "f.yaml"), InputError);
}

}  // namespace
}  // namespace lidarloop
