// The street as used (sim/street_use.hpp): each knob recovered from what street_actors draws on a long
// straight street, where the counts are large enough for the statistics to be tight.
#include <gtest/gtest.h>

#include <cmath>

#include "common/input_error.hpp"
#include "sim/scenario.hpp"
#include "sim/street_use.hpp"
#include "sim/world_description.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// A 4 km two-way street along x, 9 m curb to curb, with one crosswalk at 2000 m and no driveways, and
// a one-way street beside it.
constexpr double kLength = 4000, kWidth = 9, kCrosswalkAt = 2000, kCrosswalkWidth = 4;
const char* kWorld = R"(
name: street
origin: {lat: 31.28, lon: 121.21, alt: 0}
roads:
  - {name: main, points: [[0, 0], [4000, 0]], width: 9.0, lanes: 2, sidewalk_width: 3}
  - {name: oneway, points: [[0, 100], [1000, 100]], width: 6.0, lanes: 1, one_way: true, sidewalk_width: 3}
crosswalks:
  - {road: main, near: [2000, 0], width: 4}
)";

WorldDescription world() { return parse_world_description(kWorld, "street_world.yaml"); }

StreetUse read(const std::string& yaml) {
  const YamlReader y = YamlReader::from_string(yaml, "street.yaml");
  StreetUse street;
  read_street_use(y, y.root(), street);
  return street;
}

// Signed distance of a point from the centreline of `main` (positive left, +y).
double lateral(const Eigen::Vector2d& p) { return p.y(); }

TEST(ActorFootprint, IsTheMeshesOwnExtent) {
  for (ActorType type : {ActorType::car, ActorType::bus, ActorType::truck, ActorType::pedestrian, ActorType::cyclist}) {
    const TriangleMesh mesh = load_actor_mesh(test::data_path("assets/actors"), type, test::materials());
    Eigen::Vector2f lo = mesh.vertices.front().head<2>(), hi = lo;
    for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v.head<2>()), hi = hi.cwiseMax(v.head<2>());
    EXPECT_NEAR(actor_footprint(type).length, hi.x() - lo.x(), 1e-3) << actor_type_name(type);
    EXPECT_NEAR(actor_footprint(type).width, hi.y() - lo.y(), 1e-3) << actor_type_name(type);
  }
}

TEST(StreetUse, ParkedStallsAreTakenAtTheOccupancyBesideTheCurbAndClearOfTheCrosswalk) {
  StreetUse street = read(R"(
parking:
  occupancy: 0.85
  truck_share: 0
  stretches: [{road: main, side: both}]
)");
  const auto actors = street_actors(street, world(), 60, 7, 0);
  const double stall = street.parking.stall_length_m;
  // Stalls per side: the street less the crosswalk and its clearance on both sides.
  const double blocked = kCrosswalkWidth + 2 * street.parking.crosswalk_clearance_m;
  const double stalls = 2 * (std::floor((kCrosswalkAt - blocked / 2) / stall) +
                             std::floor((kLength - kCrosswalkAt - blocked / 2) / stall));
  const double occupancy = double(actors.size()) / stalls;
  const double sigma = std::sqrt(0.85 * 0.15 / stalls);
  EXPECT_NEAR(occupancy, 0.85, 4 * sigma) << actors.size() << " of " << stalls << " stalls";
  const double half_car = actor_footprint(ActorType::car).width / 2;
  for (const auto& a : actors) {
    ASSERT_EQ(a.plan.type, ActorType::car);
    EXPECT_EQ(a.plan.speed, 0);
    const Pose2d p = a.plan.path.pose_at(0);
    // The body's side is curb_gap from the curb face, and the car faces its side's traffic.
    EXPECT_NEAR(kWidth / 2 - std::abs(lateral({p.x, p.y})) - half_car, street.parking.curb_gap_m, 1e-9);
    EXPECT_NEAR(std::cos(p.yaw), p.y < 0 ? 1.0 : -1.0, 1e-9);
    EXPECT_GT(std::abs(p.x - kCrosswalkAt), kCrosswalkWidth / 2 + street.parking.crosswalk_clearance_m + 2);
  }
  std::cout << "[ figures  ] parked occupancy " << occupancy << " over " << stalls << " stalls (asked 0.85)\n";
}

TEST(StreetUse, ACrosswalksClearanceContinuesAcrossAClosedRoadsStart) {
  // A closed road whose centreline starts mid-straight, 2 m before a crosswalk: the clearance behind
  // the crosswalk lies at the end of the centreline, where the stretch parked at full occupancy ends.
  const WorldDescription ring = parse_world_description(R"(
name: ring
origin: {lat: 31.28, lon: 121.21, alt: 0}
roads:
  - {name: ring, closed: true, points: [[0, 0], [200, 0], [200, 100], [-200, 100], [-200, 0]], width: 9.0}
crosswalks:
  - {road: ring, near: [2, 0], width: 4}
)",
                                                        "ring.yaml");
  StreetUse street = read(R"(
parking:
  occupancy: 1.0
  truck_share: 0
  stretches: [{road: ring, side: right, from: 939.7, to: 1000}]   # nine stalls, the last ending at the start
)");
  const auto actors = street_actors(street, ring, 60, 7, 0);
  ASSERT_FALSE(actors.empty());
  const double clear = 4.0 / 2 + street.parking.crosswalk_clearance_m;
  double nearest = 1e9;
  for (const auto& a : actors) {
    const Pose2d p = a.plan.path.pose_at(0);
    ASSERT_NEAR(p.y, -kWidth / 2 + street.parking.curb_gap_m + actor_footprint(ActorType::car).width / 2, 1e-6);
    nearest = std::min(nearest, std::abs(p.x - 2.0) - street.parking.stall_length_m / 2);
  }
  EXPECT_GE(nearest, clear - 1e-6) << "a stall reaches into the crosswalk's clearance across the road's start";
  EXPECT_LT(nearest, clear + street.parking.stall_length_m);  // the next stall out is taken
}

TEST(StreetUse, NobodyParksAcrossTheMouthOfASideStreet) {
  // A side street meets `main` from the north (its left) at x = 600.
  const WorldDescription d = parse_world_description(R"(
name: junction
origin: {lat: 31.28, lon: 121.21, alt: 0}
roads:
  - {name: main, points: [[0, 0], [1200, 0]], width: 9.0}
  - {name: side, points: [[600, 0], [600, 300]], width: 8.0}
)",
                                                     "junction.yaml");
  StreetUse street = read("parking: {occupancy: 1, truck_share: 0, stretches: [{road: main}]}");
  const double clear = 8.0 / 2 + street.parking.crosswalk_clearance_m;
  bool right_side_near = false;
  for (const auto& a : street_actors(street, d, 60, 2, 0)) {
    const Pose2d p = a.plan.path.pose_at(0);
    const double half = actor_footprint(a.plan.type).length / 2;
    if (p.y > 0) {
      EXPECT_TRUE(p.x + half <= 600 - clear || p.x - half >= 600 + clear) << p.x;
    }
    right_side_near = right_side_near || (p.y < 0 && std::abs(p.x - 600) < clear);
  }
  EXPECT_TRUE(right_side_near);  // the far side of a T-junction stays a kerb to park at
}

TEST(StreetUse, VansTakeTwoStallsAtTheirShare) {
  StreetUse street =
      read("parking: {occupancy: 1, truck_share: 0.3, stretches: [{road: main, side: right, to: 1900}]}");
  const auto actors = street_actors(street, world(), 60, 3, 0);
  int trucks = 0;
  for (const auto& a : actors) trucks += a.plan.type == ActorType::truck;
  const double share = double(trucks) / double(actors.size());
  EXPECT_NEAR(share, 0.3, 4 * std::sqrt(0.3 * 0.7 / double(actors.size())));
  // Every stall is taken, and a van takes two: the vehicles fill the stretch exactly.
  const double stall = street.parking.stall_length_m;
  EXPECT_NEAR(double(actors.size() + size_t(trucks)) * stall, std::floor(1900 / stall) * stall, 2 * stall);
}

TEST(StreetUse, SidewalkPedestriansComeAtTheDensityAndSpeedAskedOnTheSidewalk) {
  StreetUse street = read(R"(
sidewalk_pedestrians: {per_100m: 2.5, speed_mps: 1.38, speed_sigma_mps: 0.2, stretches: [{road: main}]}
)");
  const auto actors = street_actors(street, world(), 60, 11, 5);
  ASSERT_EQ(actors.size(), size_t(2 * 2.5 * kLength / 100));  // both sides
  EXPECT_EQ(actors.front().plan.name, "pedestrian_5");
  double sum = 0, forward = 0;
  for (const auto& a : actors) {
    sum += a.plan.speed;
    const Pose2d p = a.plan.path.pose_at(a.plan.start_s);
    EXPECT_NEAR(std::abs(p.y), kWidth / 2 + street.sidewalk_pedestrians.from_curb_m, 1e-6);
    forward += std::cos(p.yaw) > 0;
  }
  const double n = double(actors.size());
  EXPECT_NEAR(sum / n, 1.38, 4 * 0.2 / std::sqrt(n));
  EXPECT_NEAR(forward / n, 0.5, 4 * 0.5 / std::sqrt(n));  // either way along the street
}

TEST(StreetUse, CyclistsRideWithTheirSidesTrafficNearTheCurb) {
  StreetUse street = read("cyclists: {per_km: 10, from_curb_m: 0.8, stretches: [{road: main}, {road: oneway}]}");
  const auto actors = street_actors(street, world(), 60, 5, 0);
  ASSERT_EQ(actors.size(), size_t(2 * 10 * 4 + 2 * 10 * 1));
  for (const auto& a : actors) {
    ASSERT_EQ(a.plan.type, ActorType::cyclist);
    const Pose2d p = a.plan.path.pose_at(a.plan.start_s);
    if (std::abs(p.y) < 50) {  // main: two-way, so the left side rides west
      EXPECT_NEAR(std::abs(p.y), kWidth / 2 - 0.8, 1e-6);
      EXPECT_NEAR(std::cos(p.yaw), p.y < 0 ? 1.0 : -1.0, 1e-9);
    } else {  // the one-way street: both sides ride east
      EXPECT_NEAR(std::abs(p.y - 100), 3 - 0.8, 1e-6);
      EXPECT_NEAR(std::cos(p.yaw), 1.0, 1e-9);
    }
  }
}

TEST(StreetUse, CrossingsArriveAtTheirRateAndCrossTheRoad) {
  StreetUse street = read("crossing_pedestrians: {per_minute: 6}");
  const double duration = 3600;
  const auto actors = street_actors(street, world(), duration, 9, 0);
  const double expected = 6 * duration / 60;  // Poisson: sigma = sqrt(expected)
  EXPECT_NEAR(double(actors.size()), expected, 4 * std::sqrt(expected));
  for (const auto& a : actors) {
    ASSERT_EQ(a.plan.type, ActorType::pedestrian);
    const Pose2d start = a.plan.path.pose_at(0), end = a.plan.path.pose_at(a.plan.path.length);
    // From one sidewalk to the other, across the crosswalk.
    EXPECT_NEAR(start.y * end.y, -std::pow(kWidth / 2 + 1.0, 2), 1e-6);
    EXPECT_LE(std::abs(start.x - kCrosswalkAt), street.crossing_pedestrians.spread_m + 1e-9);
    EXPECT_LT(a.plan.depart_ns, int64_t(duration * 1e9));
  }
}

TEST(StreetUse, ABusStandsAtItsStopForItsDwellTimeAtTheCurb) {
  StreetUse street = read("bus_stops: [{road: main, side: left, at: 1500, arrive_s: 20, dwell_s: 30}]");
  const auto actors = street_actors(street, world(), 90, 1, 0);
  ASSERT_EQ(actors.size(), 1u);
  const ActorPlan& bus = actors[0].plan;
  ASSERT_EQ(bus.type, ActorType::bus);
  const auto at = [&](double t) { return actor_pose2d(bus, int64_t(t * 1e9)); };
  for (double t : {20.0, 35.0, 50.0}) {
    EXPECT_NEAR(at(t).x, 1500, 1e-6) << t;
    EXPECT_NEAR(at(t).y, kWidth / 2 - street.bus_stops[0].curb_gap_m - actor_footprint(ActorType::bus).width / 2, 1e-6);
  }
  // Coming west along the left side in the centre of its lane, and gone on after its dwell.
  EXPECT_GT(at(10).x, 1500 + 50);
  EXPECT_NEAR(at(10).y, kWidth / 4, 1e-6);
  EXPECT_LT(at(60).x, 1500 - 50);
  EXPECT_NEAR(at(60).y, kWidth / 4, 1e-6);
}

TEST(StreetUse, NobodyParksInABusZone) {
  StreetUse street = read(R"(
parking: {occupancy: 1, truck_share: 0, stretches: [{road: main, side: left, to: 1900}]}
bus_stops: [{road: main, side: left, at: 1000, arrive_s: 20}]
)");
  const double zone = actor_footprint(ActorType::bus).length / 2 + street.bus_stops[0].pull_in_m;
  size_t parked = 0;
  for (const auto& a : street_actors(street, world(), 60, 1, 0)) {
    if (a.plan.speed > 0) continue;
    ++parked;
    const double x = a.plan.path.pose_at(0).x, half = actor_footprint(a.plan.type).length / 2;
    EXPECT_TRUE(x + half <= 1000 - zone || x - half >= 1000 + zone) << x;
  }
  EXPECT_GT(parked, 250u);
}

TEST(StreetUse, AVehicleDrivingThroughAParkedOneIsFound) {
  const Path along_x = make_path({{0, 0}, {100, 0}}, false);
  const auto parked_at = [](double y) {
    ActorPlan p;
    p.name = "car_3";
    p.path = make_path({{50, y}, {50.001, y}}, false);
    return std::vector<ActorPlan>{p};
  };
  const ActorFootprint car = actor_footprint(ActorType::car);
  // Two cars side by side overlap while their centres are less than a car's width apart.
  EXPECT_NE(drives_through_parked(along_x, 0, 100, car, parked_at(car.width - 0.25)).find("car_3 at (50.0, 1.6)"),
            std::string::npos);
  EXPECT_EQ(drives_through_parked(along_x, 0, 100, car, parked_at(car.width + 0.05)), "");
  EXPECT_EQ(
      drives_through_parked(along_x, 0, 100, actor_footprint(ActorType::bus), parked_at(car.width + 0.05)).substr(0, 6),
      "drives");
  // Only the stretch driven counts: stopping short of the parked car is no conflict.
  EXPECT_EQ(drives_through_parked(along_x, 0, 40, car, parked_at(0)), "");
}

TEST(StreetUse, TheSameSeedGivesTheSameStreetAndAnotherSeedAnother) {
  StreetUse street = read(R"(
parking: {stretches: [{road: main}]}
sidewalk_pedestrians: {per_100m: 1, stretches: [{road: main}]}
crossing_pedestrians: {per_minute: 2}
)");
  const auto a = street_actors(street, world(), 120, 4, 0), b = street_actors(street, world(), 120, 4, 0);
  const auto c = street_actors(street, world(), 120, 5, 0);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].plan.name, b[i].plan.name);
    EXPECT_EQ(a[i].plan.path.points, b[i].plan.path.points);
    EXPECT_EQ(a[i].plan.speed, b[i].plan.speed);
    EXPECT_EQ(a[i].plan.depart_ns, b[i].plan.depart_ns);
  }
  EXPECT_NE(a.size() == c.size() && a.front().plan.path.points == c.front().plan.path.points, true);
}

TEST(StreetUse, BadEntriesAreErrorsNamingTheFileAndEntry) {
  const auto error = [](const std::string& yaml) {
    try {
      street_actors(read(yaml), world(), 60, 1, 0);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("parking: {stretches: [{road: nowhere}]}").find("street.yaml:1:"), std::string::npos);
  EXPECT_NE(error("parking: {stretches: [{road: nowhere}]}").find("unknown road 'nowhere'"), std::string::npos);
  EXPECT_NE(error("parking: {stretches: [{road: main, from: 100, to: 9000}]}").find("must lie along road 'main'"),
            std::string::npos);
  EXPECT_NE(error("crossing_pedestrians: {per_minute: 1, crosswalks: [3]}").find("there is no crosswalk 3"),
            std::string::npos);
  EXPECT_NE(error("parking: {occupancy: 0.5}").find("stretches"), std::string::npos);
  EXPECT_NE(error("parking: {stretches: [{road: main}], occupency: 0.5}").find("occupency"), std::string::npos);
  EXPECT_NE(error("bus_stops: [{road: main, side: both, at: 10, arrive_s: 1}]").find("one side"), std::string::npos);
}

}  // namespace
}  // namespace lidarloop
