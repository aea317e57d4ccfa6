// Clutter beside the curb, read back from the mesh by ray casts: a hedge that leans over the curb
// line above its clearance, bollards and hydrants where their rows put them, a grass verge.
#include <gtest/gtest.h>

#include <string>

#include "common/input_error.hpp"
#include "sim/ray_scene.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// A 60 m road 8 m wide (curbs at y = +-4, 0.15 m high), flat, with clutter on its right side.
const std::string kWorld = R"(name: roadside
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, curb_height: 0.15, cross_slope: 0, verge_width: 1.0}
geometry: {roughness_class: none, sidewalk_cross_slope: 0, crosswalk_ramps: false}
roads:
  - {name: main, points: [[0, 0], [60, 0]]}
hedges:
  - {road: main, at: 30, length: 20, side: right, setback: 0.5, depth: 0.8, height: 1.2, overhang: 0.3}
bollards:
  - {road: main, side: right, spacing: 100, start: 5}
hydrants:
  - {road: main, side: right, start: 50}
)";

RayHit cast(const RayScene& scene, const Eigen::Vector3f& from, const Eigen::Vector3f& direction) {
  RayHit hit;
  EXPECT_TRUE(scene.intersect({from, direction}, 0, 100, hit)) << from.transpose();
  return hit;
}

// Height and material of what a ray straight down at (x, y) hits first.
std::pair<double, std::string> down(const RayScene& scene, double x, double y) {
  constexpr float kAbove = 20;
  const RayHit hit = cast(scene, {float(x), float(y), kAbove}, {0, 0, -1});
  return {kAbove - hit.range, test::materials()[hit.material].name};
}

TEST(Roadside, AHedgeLeansOverTheCurbLineAboveItsClearance) {
  const World w = test::world_from_yaml(kWorld);
  const RayScene scene(w.mesh);
  // From above, at the curb line inside the stretch: leaves at the hedge's top.
  const auto [top, leaves] = down(scene, 30, -4.0);
  EXPECT_EQ(leaves, "vegetation");
  EXPECT_NEAR(top, 0.15 + 1.2, 0.02);
  // 0.2 m into the road the overhang (0.3 m) still covers it; at 0.5 m the road is open.
  EXPECT_EQ(down(scene, 30, -3.8).second, "vegetation");
  EXPECT_EQ(down(scene, 30, -3.5).second, "asphalt");
  // Outside the stretch, the curb's top is bare.
  EXPECT_EQ(down(scene, 10, -4.05).second, "curb_concrete");
  // Below the clearance the curb's face is still in sight from the road.
  const RayHit face = cast(scene, {30, -2, 0.08f}, {0, -1, 0});
  EXPECT_EQ(test::materials()[face.material].name, "curb_concrete");
  EXPECT_NEAR(face.range, 2.0, 0.02);
  // The road-facing side leans out from the curb line at the clearance (0.4 m, the default) to 0.3 m
  // in front of it at the top: halfway up, 0.8 m above the sidewalk, it is 0.15 m over the road.
  const RayHit lean = cast(scene, {30, -2, 0.15f + 0.8f}, {0, -1, 0});
  EXPECT_EQ(test::materials()[lean.material].name, "vegetation");
  EXPECT_NEAR(lean.range, 4.0 - 0.15 - 2.0, 0.02);
}

// The same road with a driveway on each side at 30 m (6 m wide, flares 1.5 m): the hedge leaves it
// open, the hydrant planned in front of it is left out, and the verge is paved across it.
const std::string kDrivewayWorld = R"(name: roadside_driveways
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, curb_height: 0.15, cross_slope: 0, verge_width: 1.0}
geometry: {roughness_class: none, sidewalk_cross_slope: 0, crosswalk_ramps: false}
roads:
  - {name: main, points: [[0, 0], [60, 0]]}
curb_cuts:
  - {road: main, at: 30, side: right, length: 6, kind: driveway}
  - {road: main, at: 30, side: left, length: 6, kind: driveway}
hedges:
  - {road: main, at: 30, length: 40, side: right}
hydrants:
  - {road: main, side: right, start: 30, spacing: 20}
)";

TEST(Roadside, CutsStayOpen) {
  const World w = test::world_from_yaml(kDrivewayWorld);
  const RayScene scene(w.mesh);
  // Hedge: over the curb line beside the driveway (and its flares, to 34.5 m), not across it.
  EXPECT_NE(down(scene, 30, -4.0).second, "vegetation");
  EXPECT_NE(down(scene, 34, -4.0).second, "vegetation");
  EXPECT_EQ(down(scene, 36, -4.0).second, "vegetation");
  EXPECT_EQ(down(scene, 24, -4.0).second, "vegetation");
  // Hydrants: the one at 30 m would stand in the driveway; the next, at 50 m, stands.
  EXPECT_NE(down(scene, 30, -4.6).second, "vehicle_paint");
  EXPECT_EQ(down(scene, 50, -4.6).second, "vehicle_paint");
  // Verge (left side): grass away from the driveway, paved across it.
  EXPECT_EQ(down(scene, 15, 4.65).second, "grass");
  EXPECT_NE(down(scene, 30, 4.65).second, "grass");
}

TEST(Roadside, BollardsAndHydrantsStandWhereTheirRowsPutThem) {
  const World w = test::world_from_yaml(kWorld);
  const RayScene scene(w.mesh);
  // Bollard: 5 m along, 0.45 m behind the curb, 1.0 m tall on the 0.15 m curb level.
  const auto [bollard, steel] = down(scene, 5, -4.45);
  EXPECT_EQ(steel, "metal");
  EXPECT_NEAR(bollard, 0.15 + 1.0, 0.02);
  EXPECT_NE(down(scene, 5, -4.75).second, "metal");  // 0.2 m across: nothing 0.3 m from its axis
  // Hydrant: 50 m along, 0.6 m behind the curb, 0.75 m tall.
  const auto [hydrant, paint] = down(scene, 50, -4.6);
  EXPECT_EQ(paint, "vehicle_paint");
  EXPECT_NEAR(hydrant, 0.15 + 0.75, 0.02);
}

TEST(Roadside, AGrassVergeLiesBetweenTheCurbAndTheSidewalk) {
  const World w = test::world_from_yaml(kWorld);
  const RayScene scene(w.mesh);
  // Verge right behind the curb's top, from 4 + 0.15 = 4.15 m to 5.15 m from the centreline, on the
  // left side (the hedge covers it on the right).
  EXPECT_EQ(down(scene, 20, 4.95).second, "grass");
  EXPECT_NEAR(down(scene, 20, 4.95).first, 0.15 + 0.01, 0.01);
  EXPECT_EQ(down(scene, 20, 4.2).second, "grass");
  EXPECT_EQ(down(scene, 20, 4.1).second, "curb_concrete");
  EXPECT_NE(down(scene, 20, 5.2).second, "grass");
}

TEST(Roadside, BadValuesAreErrorsAtTheirLine) {
  std::string message;
  try {
    test::world_from_yaml(
        "name: bad\norigin: {lat: 31.28, lon: 121.21}\nroads:\n  - {name: main, points: [[0, 0], [60, 0]]}\n"
        "hedges:\n  - {road: main, at: 10, height: -1}\n");
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("test_world.yaml:6:"), std::string::npos) << message;
  EXPECT_NE(message.find("height"), std::string::npos) << message;
}

}  // namespace
}  // namespace lidarloop
