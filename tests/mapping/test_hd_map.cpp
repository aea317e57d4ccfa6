// The HD map: the curb layer's queries, and the intensity layer a mapping drive builds (paint bright,
// traffic raising variance).
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include <filesystem>

#include "localizer/curb_layer.hpp"
#include "localizer/hd_map.hpp"
#include "mapping/mapping_drive.hpp"
#include "sim/actor_assets.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

TEST(CurbLayer, DensifiesAndAnswersWindowsLikeBruteForce) {
  CurbMap map;
  map.origin = {31.28, 121.21, 0};
  map.curbs = {{{0, 0}, {10, 0}, {10, 7.3}}, {{-5, -5}, {-5, 20}}};
  CurbLayer layer(map);
  for (size_t i = 1; i < layer.points().size(); ++i) {
    const double gap = (layer.points()[i] - layer.points()[i - 1]).norm();
    if (gap < 1.0) {  // within a line (the lines are far apart)
      EXPECT_LE(gap, CurbLayer::kDefaultSpacing + 1e-9);
    }
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-10, 20);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector2d c(u(rng), u(rng));
    const double half = 1 + std::abs(u(rng)) / 2;
    size_t expected = 0;
    for (const auto& p : layer.points()) expected += std::abs(p.x() - c.x()) <= half && std::abs(p.y() - c.y()) <= half;
    EXPECT_EQ(layer.window(c, half).size(), expected);
  }
  EXPECT_NEAR(layer.distance({5, 2}), 2.0, 1e-9);
  EXPECT_NEAR(layer.distance({12, 3.05}), 2.0, 0.01);
  // Moving the layer keeps its index valid.
  const CurbLayer moved = std::move(layer);
  EXPECT_NEAR(moved.distance({5, 2}), 2.0, 1e-9);
}

// A 200 m two-way road with dashed lane lines, edge lines and a crosswalk at x = 100.
constexpr double kRoadWidth = 8.0, kCrosswalkX = 100.0, kCrosswalkWidth = 4.0;
const char* kStraight = R"(name: survey
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: dashed, edge_lines: true, sidewalk_width: 3}
roads:
  - {name: main, points: [[0, 0], [200, 0]]}
crosswalks:
  - {road: main, at: 100, width: 4.0}
)";

struct Survey {
  static const IntensityMapBuilder& map(bool traffic) {
    static std::map<bool, IntensityMapBuilder> built;
    auto it = built.find(traffic);
    if (it == built.end()) {
      const WorldDescription d = parse_world_description(kStraight, "survey.yaml");
      const World w = build_world(d, test::materials(), test::data_path("assets/actors"));
      MappingOptions o;
      o.traffic = traffic;
      it =
          built
              .emplace(traffic, run_mapping_drive(d, w, test::materials(), test::data_path("assets/actors"), o, "test"))
              .first;
    }
    return it->second;
  }
};

// Mean of the cells' means (or variances) over cell centres that satisfy `where`.
template <class Where>
double average(const IntensityMapBuilder& map, Where where, bool variance, int* n = nullptr) {
  const double res = map.header().resolution_m;
  double sum = 0;
  int count = 0;
  for (double x = 20; x < 180; x += res)
    for (double y = -kRoadWidth / 2; y < kRoadWidth / 2; y += res) {
      const Eigen::Vector2d c(std::floor(x / res) * res + res / 2, std::floor(y / res) * res + res / 2);
      if (!where(c)) continue;
      const auto cell = map.cell(c);
      if (!cell || cell->count < 3) continue;
      sum += variance ? cell->variance() : cell->mean;
      ++count;
    }
  if (n) *n = count;
  return count ? sum / count : 0;
}

bool on_crosswalk_stripe(const Eigen::Vector2d& c) {
  // The world's defaults: stripes 0.45 m wide with 0.6 m gaps, as many as fit between 0.6 m margins,
  // centred on the road; 4 m long. Keep 0.1 m clear of their edges.
  constexpr double kStripe = 0.45, kGap = 0.6, kPeriod = kStripe + kGap, kClear = 0.1;
  const int stripes = int((kRoadWidth - 2 * kGap) / kPeriod);
  if (std::abs(c.x() - kCrosswalkX) > kCrosswalkWidth / 2 - kClear) return false;
  for (int k = 0; k < stripes; ++k)
    if (std::abs(c.y() - (k - (stripes - 1) / 2.0) * kPeriod) < kStripe / 2 - kClear) return true;
  return false;
}

bool plain_asphalt(const Eigen::Vector2d& c) {
  // Between the centre line and the edge lines, away from the crosswalk and from all paint.
  const double y = std::abs(c.y());
  return std::abs(c.x() - kCrosswalkX) > 6 && y > 0.5 && y < kRoadWidth / 2 - 0.8;
}

TEST(IntensityLayer, PaintIsBrighterThanAsphaltInTheSurveyedMap) {
  const IntensityMapBuilder& map = Survey::map(false);
  int n_paint = 0, n_asphalt = 0;
  const double paint = average(map, on_crosswalk_stripe, false, &n_paint);
  const double asphalt = average(map, plain_asphalt, false, &n_asphalt);
  ASSERT_GT(n_paint, 100);
  ASSERT_GT(n_asphalt, 1000);
  EXPECT_GT(paint, 3.0 * asphalt) << "crosswalk " << paint << ", asphalt " << asphalt;
  std::cout << "[ figures  ] crosswalk cells mean " << paint << ", asphalt " << asphalt << "\n";
}

TEST(IntensityLayer, TrafficRaisesTheVarianceOfTheCellsItCrosses) {
  // The oncoming lane (y > 0 when driving +x) is where the mapping drive meets traffic.
  auto oncoming = [](const Eigen::Vector2d& c) {
    return c.y() > 0.6 && c.y() < kRoadWidth / 2 - 0.6 && std::abs(c.x() - kCrosswalkX) > 6;
  };
  int n_clean = 0, n_busy = 0;
  const double clean = average(Survey::map(false), oncoming, true, &n_clean);
  const double busy = average(Survey::map(true), oncoming, true, &n_busy);
  ASSERT_GT(n_clean, 1000);
  ASSERT_GT(n_busy, 1000);
  EXPECT_GT(busy, 1.3 * clean) << "variance with traffic " << busy << ", without " << clean;
  std::cout << "[ figures  ] oncoming-lane cell variance with traffic " << busy << ", without " << clean << "\n";
}

// The survey day's parked cars: the road under a parked car is hidden from the survey (no ground
// cells there), the road beside it is not; the cars are drawn for another day than the drive's, at the
// same occupancy, and they change the map's options (its cache key).
TEST(IntensityLayer, TheSurveyDaysParkedCarsHideTheRoadUnderThemFromTheMap) {
  const WorldDescription d = parse_world_description(kStraight, "survey.yaml");
  const World w = build_world(d, test::materials(), test::data_path("assets/actors"));
  ParkingConfig parking;
  parking.stretches.push_back({"survey.yaml:1", "main", RoadSide::right, 20, 80});
  parking.occupancy = 1.0;
  parking.truck_share = 0;
  MappingOptions o;
  o.parked = survey_day_parking(parking, d, o.seed);
  ASSERT_EQ(o.parked.size(), size_t(60 / parking.stall_length_m));  // every stall, at full occupancy
  EXPECT_NE(o.describe(), MappingOptions{}.describe());
  const IntensityMapBuilder map =
      run_mapping_drive(d, w, test::materials(), test::data_path("assets/actors"), o, "parked");
  const ActorFootprint car = actor_footprint(ActorType::car);
  // Returns from the road in the footprints' middles (0.5 m in from the ends and sides), with the cars
  // and on the empty street. Rays still reach under a car between its wheels, at a grazing angle.
  double hits_under = 0, hits_empty = 0;
  for (const ActorPlan& a : o.parked) {
    const Pose2d p = actor_pose2d(a, 0);
    for (double dx = -car.length / 2 + 0.5; dx <= car.length / 2 - 0.5; dx += 0.2)
      for (double dy = -car.width / 2 + 0.5; dy <= car.width / 2 - 0.5; dy += 0.2) {
        const Eigen::Vector2d c(p.x + dx, p.y + dy);
        hits_under += map.cell(c).value_or(IntensityCell{}).count;
        hits_empty += Survey::map(false).cell(c).value_or(IntensityCell{}).count;
      }
  }
  ASSERT_GT(hits_empty, 10000);
  EXPECT_LT(hits_under, 0.2 * hits_empty)
      << hits_under << " returns under the parked cars, " << hits_empty << " on the empty street";
  // The drive day's cars for the same stretch (a scenario's seed) stand elsewhere: another day.
  StreetUse street;
  street.parking = parking;
  street.parking.occupancy = 0.5;
  parking.occupancy = 0.5;
  const auto drive_day = street_actors(street, d, 0, o.seed, 0);
  const auto survey_day = survey_day_parking(parking, d, o.seed);
  size_t same = 0;
  for (const StreetActor& a : drive_day)
    for (const ActorPlan& b : survey_day) same += (actor_pose2d(a.plan, 0).x == actor_pose2d(b, 0).x);
  EXPECT_LT(same, drive_day.size()) << "the survey day parked exactly as the drive day";
  // A scenario may survey an empty street.
  const YamlReader yaml = YamlReader::from_string("survey: {parked_on_survey_day: false}\n", "survey.yaml");
  MappingOptions empty_street;
  read_survey_options(yaml, yaml.root()["survey"], empty_street);
  EXPECT_FALSE(empty_street.parked_on_survey_day);
  std::cout << "[ figures  ] road returns under the survey day's parked cars: " << hits_under << " against "
            << hits_empty << " on the empty street\n";
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

// A small saved map of world `name` (with its curbs) in a fresh folder.
std::string saved_map(const std::string& folder, const std::string& name, const Geodetic& curb_origin) {
  const std::string dir = testing::TempDir() + "/hd_map_" + folder;
  IntensityMapHeader h;
  h.world = name;
  h.world_hash = "0123456789abcdef";
  h.origin = {31.28, 121.21, 0};
  h.tile_cells = 16;
  IntensityMapBuilder b(h);
  for (double x = -5; x < 5; x += 0.1) b.add({x, 0.5}, 10 + x);
  b.save(dir);
  write_curb_map(dir + "/curbs.geojson", CurbMap{curb_origin, name, {{{-5, 4}, {5, 4}}}, {}});
  return dir;
}

TEST(HdMap, OpensBothLayersOfTheExpectedWorld) {
  const std::string dir = saved_map("good", "campus", {31.28, 121.21, 0});
  HdMap map = open_hd_map(dir, "campus");
  EXPECT_NEAR(map.curbs.distance({0, 0}), 4.0, 1e-6);
  const auto cell = map.intensity.cell({1.05, 0.55});
  ASSERT_TRUE(cell.has_value());
  EXPECT_NEAR(cell->mean, 11.0, 0.1);
}

TEST(HdMap, AMapOfAnotherWorldOrMismatchedLayersIsAnError) {
  const std::string dir = saved_map("other", "large", {31.28, 121.21, 0});
  try {
    open_hd_map(dir, "campus");
    ADD_FAILURE() << "accepted a map of another world";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/map.yaml: this is a map of world 'large', not of 'campus'"),
              std::string::npos)
        << e.what();
  }
  const std::string shifted = saved_map("shifted", "campus", {31.29, 121.21, 0});
  EXPECT_THROW(open_hd_map(shifted, "campus"), InputError);
  const std::string no_curbs = saved_map("no_curbs", "campus", {31.28, 121.21, 0});
  std::filesystem::remove(no_curbs + "/curbs.geojson");
  EXPECT_THROW(open_hd_map(no_curbs, "campus"), InputError);
}

TEST(HdMap, ACurbFarOutsideTheIntensityTilesIsAnError) {
  // The tiles are 3.2 m and cover x in [-6.4, 6.4), y in [0, 3.2): a curb one tile beyond them is kept,
  // one running 111 km north (a degree of latitude, as a corrupt file had it) is refused before it is
  // densified into millions of points.
  const Geodetic origin{31.28, 121.21, 0};
  const std::string dir = saved_map("far_curb", "campus", origin);
  write_curb_map(dir + "/curbs.geojson", CurbMap{origin, "campus", {{{-9, 6}, {9, 6}}}, {}});
  EXPECT_NEAR(open_hd_map(dir, "campus").curbs.distance({0, 0}), 6.0, 1e-6);
  write_curb_map(dir + "/curbs.geojson", CurbMap{origin, "campus", {{{-5, 4}, {5, 111000}}}, {}});
  try {
    open_hd_map(dir, "campus");
    ADD_FAILURE() << "accepted a curb 111 km outside the map";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/curbs.geojson: feature 0 has a point at (5.0, 111000.0) m"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("outside the intensity layer's tiles"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lidarloop
