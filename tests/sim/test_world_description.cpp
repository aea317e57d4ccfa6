// Parsing and validating world descriptions (maps/<world>/world.yaml). Errors must be InputErrors of the
// form "file:line:col: what is wrong", pointing at the offending node.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/polyline.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {
namespace {

const std::string kFile = "name.yaml";

// "name.yaml:LINE:COL" of the first character of `target` inside the unique occurrence of `context` in
// `yaml` (1-based, as editors count). Lets each test say *which* node an error must point at.
std::string location(const std::string& yaml, const std::string& context, const std::string& target) {
  const size_t at = yaml.find(context);
  EXPECT_NE(at, std::string::npos) << "'" << context << "' is not in the test YAML";
  EXPECT_EQ(yaml.find(context, at + 1), std::string::npos) << "'" << context << "' is not unique in the test YAML";
  const size_t inner = context.find(target);
  EXPECT_NE(inner, std::string::npos) << "'" << target << "' is not in '" << context << "'";
  const size_t pos = at + inner;
  const size_t line_start = yaml.rfind('\n', pos) == std::string::npos ? 0 : yaml.rfind('\n', pos) + 1;
  const long line = 1 + std::count(yaml.begin(), yaml.begin() + long(pos), '\n');
  return kFile + ":" + std::to_string(line) + ":" + std::to_string(pos - line_start + 1);
}

// Parsing must throw an InputError starting with "where: " and containing `what`.
void expect_error(const std::string& yaml, const std::string& where, const std::string& what) {
  try {
    parse_world_description(yaml, kFile);
    ADD_FAILURE() << "no error; expected " << where << ": ..." << what;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(where + ": ", 0), 0u) << "expected the location " << where << " in: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "expected '" << what << "' in: " << msg;
  }
}

// A valid header; tests append roads and objects after it (it ends with a newline).
const std::string kHeader = R"(name: tiny
origin: {lat: 31.2856, lon: 121.2147}
)";

// ---------------------------------------------------------------------------------------------- valid input

TEST(WorldDescription, MinimalWorldGetsDefaults) {
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [100, 0]]
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  EXPECT_EQ(w.name, "tiny");
  EXPECT_EQ(w.file, kFile);
  EXPECT_DOUBLE_EQ(w.origin.lat_deg, 31.2856);
  EXPECT_DOUBLE_EQ(w.origin.lon_deg, 121.2147);
  EXPECT_EQ(w.origin.alt_m, 0.0);
  ASSERT_EQ(w.roads.size(), 1u);
  const RoadSpec& r = w.roads[0];
  const RoadSpec defaults;
  EXPECT_EQ(r.name, "main");
  EXPECT_EQ(r.where, location(yaml, "- name: main", "name"));
  EXPECT_EQ(r.where, "name.yaml:4:5");  // the same, counted by hand
  EXPECT_EQ(r.width, defaults.width);
  EXPECT_EQ(r.lanes, defaults.lanes);
  EXPECT_EQ(r.one_way, false);
  EXPECT_EQ(r.closed, false);
  EXPECT_EQ(r.marking, MarkingStyle::dashed);
  EXPECT_EQ(r.edge_lines, true);
  EXPECT_EQ(r.curb_height, defaults.curb_height);
  EXPECT_EQ(r.sidewalk_width, defaults.sidewalk_width);
  EXPECT_EQ(r.smoothing_radius, 0.0);
  // Without smoothing the centreline is the line as written.
  ASSERT_EQ(r.centreline.size(), 2u);
  EXPECT_EQ(r.centreline[0], Eigen::Vector2d(0, 0));
  EXPECT_EQ(r.centreline[1], Eigen::Vector2d(100, 0));
  EXPECT_EQ(w.geometry.corner_radius, WorldGeometryParams{}.corner_radius);
  EXPECT_TRUE(w.crosswalks.empty() && w.stop_lines.empty() && w.buildings.empty() && w.poles.empty() &&
              w.trees.empty() && w.parked.empty());
  EXPECT_EQ(w.road("main"), &w.roads[0]);
  EXPECT_EQ(w.road("nope"), nullptr);
}

TEST(WorldDescription, RoadDefaultsAndOverrides) {
  const std::string yaml = kHeader + R"(road_defaults: {width: 9.0, curb_height: 0.12, marking: solid}
geometry: {corner_radius: 12}
roads:
  - {name: a, points: [[0, 0], [100, 0]]}
  - {name: b, points: [[0, 50], [100, 50]], width: 5.5, one_way: true, lanes: 1, marking: none}
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  EXPECT_EQ(w.geometry.corner_radius, 12.0);
  EXPECT_EQ(w.road("a")->width, 9.0);
  EXPECT_EQ(w.road("a")->curb_height, 0.12);
  EXPECT_EQ(w.road("a")->marking, MarkingStyle::solid);
  EXPECT_EQ(w.road("b")->width, 5.5);
  EXPECT_EQ(w.road("b")->curb_height, 0.12);  // from the defaults
  EXPECT_TRUE(w.road("b")->one_way);
  EXPECT_EQ(w.road("b")->lanes, 1);
  EXPECT_EQ(w.road("b")->marking, MarkingStyle::none);
}

TEST(WorldDescription, SmoothedCornerIsATangentArc) {
  // A right-angle corner at (100, 0) rounded with radius R: the arc runs from (100-R, 0) to (100, R)
  // around the centre (100-R, R), and the centreline is 2 x 100 - 2R + pi R / 2 long.
  constexpr double kRadius = 20.0, kLeg = 100.0;
  const std::string yaml = kHeader + R"(roads:
  - {name: bend, points: [[0, 0], [100, 0], [100, 100]], smoothing_radius: 20}
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  const RoadSpec& r = *w.road("bend");
  const Eigen::Vector2d centre(kLeg - kRadius, kRadius);
  EXPECT_NEAR(polyline_length(r.centreline), 2 * kLeg - 2 * kRadius + std::numbers::pi * kRadius / 2, 0.01);
  EXPECT_EQ(r.centreline.front(), Eigen::Vector2d(0, 0));
  EXPECT_EQ(r.centreline.back(), Eigen::Vector2d(kLeg, kLeg));
  int on_arc = 0;
  for (const auto& p : r.centreline) {
    if (p.x() > kLeg - kRadius + 1e-9 && p.y() < kRadius - 1e-9) {  // strictly inside the corner square
      EXPECT_NEAR((p - centre).norm(), kRadius, 1e-9) << p.transpose();
      ++on_arc;
    }
    EXPECT_LE(p.x(), kLeg + 1e-9);  // never cuts outside the corner
  }
  EXPECT_GE(on_arc, 10);  // arcs are split into steps of a few degrees
}

TEST(WorldDescription, ClosedRoadRepeatsItsFirstPoint) {
  const std::string yaml = kHeader + R"(roads:
  - {name: loop, closed: true, points: [[0, 0], [100, 0], [100, 50], [0, 50]]}
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  const RoadSpec& r = *w.road("loop");
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.centreline.front(), r.centreline.back());
  EXPECT_NEAR(polyline_length(r.centreline), 300.0, 1e-9);
}

TEST(WorldDescription, SmoothedClosedRoadRoundsEveryCorner) {
  // A 100 m x 50 m loop with all four right-angle corners rounded (radius R): length 300 - 4 (2R - pi R/2).
  constexpr double kRadius = 20.0, kPerimeter = 300.0, kChordTolerance = 0.05;
  const std::string yaml = kHeader + R"(roads:
  - {name: loop, closed: true, points: [[0, 0], [100, 0], [100, 50], [0, 50]], smoothing_radius: 20}
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  const RoadSpec& r = *w.road("loop");
  EXPECT_EQ(r.centreline.front(), r.centreline.back());
  EXPECT_NEAR(polyline_length(r.centreline), kPerimeter - 4 * (2 * kRadius - std::numbers::pi * kRadius / 2),
              kChordTolerance);
  int zero_length = 0;
  for (size_t i = 1; i < r.centreline.size(); ++i) zero_length += (r.centreline[i] - r.centreline[i - 1]).norm() < 1e-6;
  EXPECT_EQ(zero_length, 0) << "zero-length centreline segments";
  // Each corner is R (sqrt 2 - 1) from its arc.
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(100, 0), Eigen::Vector2d(100, 50), Eigen::Vector2d(0, 50)}) {
    double nearest = INFINITY;
    for (const auto& p : r.centreline) nearest = std::min(nearest, (p - corner).norm());
    EXPECT_NEAR(nearest, kRadius * (std::sqrt(2.0) - 1), 0.01) << "corner " << corner.transpose();
  }
}

TEST(WorldDescription, CrosswalkNearIsProjectedOntoTheRoad) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0], [100, 100]]}
crosswalks:
  - {road: main, near: [30, 4]}
  - {road: main, near: [103, 40], width: 6}
  - {road: main, at: 12.5}
)";
  const WorldDescription w = parse_world_description(yaml, kFile);
  ASSERT_EQ(w.crosswalks.size(), 3u);
  EXPECT_NEAR(w.crosswalks[0].at, 30.0, 1e-9);
  EXPECT_NEAR(w.crosswalks[1].at, 140.0, 1e-9);  // 100 m along x, then 40 m up
  EXPECT_EQ(w.crosswalks[1].width, 6.0);
  EXPECT_EQ(w.crosswalks[2].at, 12.5);
  EXPECT_EQ(w.crosswalks[2].where, location(yaml, "- {road: main, at: 12.5}", "{"));
}

TEST(WorldDescription, CampusFileLoads) {
  // The shipped world must stay valid; its errors would name the file.
  const WorldDescription w = load_world_description(std::string(LIDARLOOP_DATA_DIR) + "/maps/campus/world.yaml");
  EXPECT_EQ(w.name, "campus");
  EXPECT_GE(w.roads.size(), 2u);
}

TEST(WorldDescription, MissingFileIsAnInputError) {
  const std::string path = "/nonexistent_dir_lidarloop/world.yaml";
  try {
    load_world_description(path);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------- errors

TEST(WorldDescriptionErrors, YamlSyntaxError) {
  // The second closing brace is the error: line 2, column 25.
  const std::string yaml = R"(name: broken
origin: {lat: 1, lon: 2}}
roads: []
)";
  expect_error(yaml, "name.yaml:2:25", "YAML syntax error");
}

TEST(WorldDescriptionErrors, UnknownTopLevelKey) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
buildingz: []
)";
  expect_error(yaml, "name.yaml:5:1", "unknown key 'buildingz'");
}

TEST(WorldDescriptionErrors, UnknownRoadKey) {
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [100, 0]]
    lanez: 2
)";
  expect_error(yaml, "name.yaml:6:5", "unknown key 'lanez'");
  EXPECT_EQ(location(yaml, "lanez: 2", "lanez"), "name.yaml:6:5");
}

TEST(WorldDescriptionErrors, MissingRoads) {
  // Reported at the document's root mapping, which starts at line 1, column 1.
  expect_error(kHeader, "name.yaml:1:1", "missing key 'roads'");
}

TEST(WorldDescriptionErrors, EmptyRoadList) {
  const std::string yaml = kHeader + "roads: []\n";
  expect_error(yaml, location(yaml, "roads: []", "["), "at least one road");
}

TEST(WorldDescriptionErrors, RoadWithOnePoint) {
  const std::string yaml = kHeader + R"(roads:
  - name: stub
    points: [[0, 0]]
)";
  expect_error(yaml, "name.yaml:5:13", "road 'stub' needs at least 2 points");
}

TEST(WorldDescriptionErrors, ClosedRoadWithTwoPoints) {
  const std::string yaml = kHeader + R"(roads:
  - {name: ring, closed: true, points: [[0, 0], [10, 0]]}
)";
  expect_error(yaml, location(yaml, "points: [[0, 0], [10, 0]]", "[["), "needs at least 3 points");
}

TEST(WorldDescriptionErrors, ZeroLengthSegment) {
  // Points 1 and 2 coincide; the error points at the repeated point.
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [50, 0], [50, 0], [100, 0]]
)";
  expect_error(yaml, "name.yaml:5:31", "zero-length segment between points 1 and 2");
}

TEST(WorldDescriptionErrors, SelfIntersectingRoad) {
  // A bow tie: segment 0 crosses segment 2 at (5, 5).
  const std::string yaml = kHeader + R"(roads:
  - name: bowtie
    points: [[0, 0], [10, 10], [10, 0], [0, 10]]
)";
  expect_error(yaml, "name.yaml:5:13", "road 'bowtie' intersects itself (segments 0 and 2)");
}

TEST(WorldDescriptionErrors, SelfIntersectingClosedRoad) {
  // A closed figure of eight: its closing segment (3 -> 0) crosses segment 1.
  const std::string yaml = kHeader + R"(roads:
  - {name: eight, closed: true, points: [[0, 0], [10, 0], [0, 10], [10, 10]]}
)";
  expect_error(yaml, location(yaml, "points: [[0, 0], [10, 0], [0, 10], [10, 10]]", "[["), "intersects itself");
}

TEST(WorldDescriptionErrors, RoadDoublingBackOnItself) {
  const std::string yaml = kHeader + R"(roads:
  - name: hairpin
    points: [[0, 0], [100, 0], [40, 0]]
)";
  // Reported at the point where it turns back.
  expect_error(yaml, "name.yaml:5:22", "road 'hairpin' turns back on itself at point 1");
}

TEST(WorldDescriptionErrors, DuplicateKey) {
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [100, 0]]
    width: 8
    width: 50
)";
  expect_error(yaml, "name.yaml:7:5", "width");
}

TEST(WorldDescriptionErrors, WidthOutOfRange) {
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [100, 0]]
    width: 55
)";
  expect_error(yaml, "name.yaml:6:12", "width = 55 is out of range [2.5, 40]");
}

TEST(WorldDescriptionErrors, WidthNotANumber) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]], width: wide}
)";
  expect_error(yaml, location(yaml, "width: wide", "wide"), "width must be a finite number");
}

TEST(WorldDescriptionErrors, BadMarkingValue) {
  const std::string yaml = kHeader + R"(roads:
  - name: main
    points: [[0, 0], [100, 0]]
    marking: dotted
)";
  expect_error(yaml, "name.yaml:6:14", "marking must be solid, dashed or none, got 'dotted'");
}

TEST(WorldDescriptionErrors, BadMarkingInRoadDefaults) {
  const std::string yaml = kHeader + R"(road_defaults: {marking: zigzag}
roads:
  - {name: main, points: [[0, 0], [100, 0]]}
)";
  expect_error(yaml, location(yaml, "marking: zigzag", "zigzag"), "got 'zigzag'");
}

TEST(WorldDescriptionErrors, CrosswalkOnUnknownRoad) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
crosswalks:
  - {road: mian, at: 20}
)";
  expect_error(yaml, "name.yaml:6:12", "unknown road 'mian'");
}

TEST(WorldDescriptionErrors, CrosswalkNearOnUnknownRoad) {
  // With 'near' the road is needed to project the point; same error, same place.
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
crosswalks:
  - {road: mian, near: [20, 0]}
)";
  expect_error(yaml, location(yaml, "road: mian", "mian"), "unknown road 'mian'");
}

TEST(WorldDescriptionErrors, CrosswalkBeyondRoadEnd) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
crosswalks:
  - {road: main, at: 120}
)";
  expect_error(yaml, "name.yaml:6:22", "beyond the end of road 'main'");
}

TEST(WorldDescriptionErrors, StopLineBeyondRoadEnd) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
stop_lines:
  - {road: main, at: 100.5, side: left}
)";
  expect_error(yaml, location(yaml, "at: 100.5", "100.5"), "beyond the end of road 'main'");
}

TEST(WorldDescriptionErrors, CrosswalkWithAtAndNear) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
crosswalks:
  - {road: main, at: 20, near: [20, 0]}
)";
  expect_error(yaml, location(yaml, "- {road: main, at: 20", "{"), "either 'at' or 'near'");
}

TEST(WorldDescriptionErrors, DuplicateRoadName) {
  // Reported at the second use of the name.
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
  - {name: main, points: [[0, 50], [100, 50]]}
)";
  expect_error(yaml, "name.yaml:5:12", "road name 'main' is used twice");
}

TEST(WorldDescriptionErrors, UnknownParkedVehicleType) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
parked_vehicles:
  - {position: [50, 20], type: tank}
)";
  expect_error(yaml, "name.yaml:6:32", "unknown vehicle type 'tank' (expected one of: car, bus, truck");
}

TEST(WorldDescriptionErrors, BadRowSide) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
trees:
  - {road: main, side: middle}
)";
  expect_error(yaml, location(yaml, "side: middle", "middle"), "side must be left, right or both");
}

TEST(WorldDescriptionErrors, PoleRowOnUnknownRoad) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
poles:
  - {road: side_street}
)";
  expect_error(yaml, location(yaml, "road: side_street", "side_street"), "unknown road 'side_street'");
}

TEST(WorldDescriptionErrors, OriginOutOfRange) {
  const std::string yaml = R"(name: polar
origin: {lat: 89.5, lon: 10}
roads:
  - {name: main, points: [[0, 0], [100, 0]]}
)";
  expect_error(yaml, "name.yaml:2:15", "lat = 89.5 is out of range");
}

TEST(WorldDescriptionErrors, SmallBuilding) {
  const std::string yaml = kHeader + R"(roads:
  - {name: main, points: [[0, 0], [100, 0]]}
buildings:
  - {centre: [50, 40], size: [0.5, 10]}
)";
  expect_error(yaml, location(yaml, "size: [0.5, 10]", "["), "building size must be at least 1 m");
}

}  // namespace
}  // namespace lidarloop
