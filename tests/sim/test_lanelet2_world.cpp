// A world from a Lanelet2 map (sim/lanelet2_world.hpp), on small maps built in code whose geometry is
// known: a straight two-lane road between two curbstones; and the real Karlsruhe map when it is there.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "sim/actor_assets.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/polyline.hpp"
#include "sim/ray_scene.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr double kLength = 60, kHalfWidth = 3.5;  // m: the road runs along x from 0 to kLength

MaterialId material(const std::string& name) { return test::materials().id(name, "test"); }

Lanelet2LineString line(Lanelet2Id id, const std::string& type, const std::string& subtype,
                        std::vector<Eigen::Vector3d> points) {
  Lanelet2LineString s;
  s.id = id;
  s.type = type;
  s.subtype = subtype;
  s.tags["type"] = type;
  if (!subtype.empty()) s.tags["subtype"] = subtype;
  s.points = std::move(points);
  for (size_t i = 0; i < s.points.size(); ++i) s.point_ids.push_back(id * 100 + Lanelet2Id(i));
  return s;
}

std::vector<Eigen::Vector3d> along(double y, double x0 = 0, double x1 = kLength) {
  return {{x0, y, 0}, {0.5 * (x0 + x1), y, 0}, {x1, y, 0}};
}

// Two lanes along +x: right lane between the centre line (y = 0) and the right edge (y = -3.5), left
// lane between the left edge (y = 3.5) and the centre line. The edges are `left_type` / `right_type`.
Lanelet2Map straight_road(const std::string& left_type, const std::string& left_sub, const std::string& right_type,
                          const std::string& right_sub) {
  Lanelet2Map map;
  map.file = "straight.osm";
  map.country = "de";
  map.lines[1] = line(1, left_type, left_sub, along(kHalfWidth));
  map.lines[2] = line(2, "line_thin", "dashed", along(0));
  map.lines[3] = line(3, right_type, right_sub, along(-kHalfWidth));
  Lanelet2Lanelet right;
  right.id = 10, right.subtype = "road", right.left = 2, right.right = 3;
  right.left_points = map.lines[2].points, right.right_points = map.lines[3].points;
  Lanelet2Lanelet left;
  left.id = 11, left.subtype = "road", left.left = 1, left.right = 2;
  left.left_points = map.lines[1].points, left.right_points = map.lines[2].points;
  map.lanelets = {right, left};
  return map;
}

Lanelet2WorldParams smooth_params() {
  Lanelet2WorldParams p;
  p.geometry.roughness_class = '-';  // a pavement as smooth as a drawing: heights are exact
  p.geometry.margin = 10;
  return p;
}

World build(const Lanelet2Map& map, const Lanelet2WorldParams& params, Lanelet2BuildReport* report = nullptr) {
  return build_lanelet2_world(map, params, test::materials(), test::data_path("assets/actors"), report);
}

// Height of the first surface a ray straight down meets at (x, y), and its material.
std::optional<std::pair<double, MaterialId>> down(const RayScene& scene, double x, double y) {
  RayHit hit;
  if (!scene.intersect({Eigen::Vector3f(float(x), float(y), 10.f), Eigen::Vector3f(0, 0, -1)}, 0, 20, hit))
    return std::nullopt;
  return std::make_pair(10.0 - hit.range, hit.material);
}

TEST(Lanelet2World, PavementCurbFaceAndTopWhereTheStandardsPutThem) {
  Lanelet2BuildReport report;
  const World w = build(straight_road("curbstone", "high", "curbstone", "high"), smooth_params(), &report);
  const Lanelet2Standards de = lanelet2_standards("de");
  RayScene scene(w.mesh);
  // Pavement: rising from the edge at the cross slope, up to the crown one lane in.
  for (const double y : {-2.5, -1.0, 1.5, 3.0}) {
    const auto hit = down(scene, 30.3, y);
    ASSERT_TRUE(hit) << y;
    EXPECT_NEAR(hit->first, de.cross_slope * std::min(kHalfWidth - std::abs(y), de.crown_distance), 1e-3) << y;
    EXPECT_EQ(hit->second, material("asphalt"));
  }
  // The curb face: a horizontal ray across the road below the curb's top meets it on the curbstone's line.
  for (const double side : {1.0, -1.0}) {
    RayHit hit;
    const Eigen::Vector3f from(31.1f, float(side * 3.0), 0.06f), dir(0, float(side), 0);
    ASSERT_TRUE(scene.intersect({from, dir}, 0, 10, hit));
    EXPECT_NEAR(3.0 + hit.range, kHalfWidth, 0.01);
    EXPECT_EQ(hit.material, material("curb_concrete"));
    // Its top, right behind the line, at the standard's reveal above the pavement at its foot (0 there).
    const auto top = down(scene, 31.1, side * (kHalfWidth + 0.005));
    ASSERT_TRUE(top);
    EXPECT_NEAR(top->first, de.curb_high, 0.005);
    const auto behind = down(scene, 31.1, side * (kHalfWidth + 1.0));
    ASSERT_TRUE(behind);
    EXPECT_NEAR(behind->first, de.curb_high, 0.005);
    EXPECT_NEAR(w.raised_level({31.1, side * (kHalfWidth + 1.0)}), de.curb_high, 0.005);
  }
  // World::ground: the pavement on the carriageway, the raised ground beyond.
  EXPECT_NEAR(w.ground()({30, -kHalfWidth + 0.5}), de.cross_slope * 0.5, 1e-6);
  EXPECT_NEAR(w.ground()({30, -kHalfWidth - 0.5}), de.curb_high, 1e-3);
  EXPECT_EQ(report.curbstones_high, 2);
  EXPECT_EQ(report.road_lanelets, 2);
  EXPECT_TRUE(report.warnings.empty());
}

TEST(Lanelet2World, CurbLinesAreTheCurbstoneWays) {
  const Lanelet2Map map = straight_road("curbstone", "high", "curbstone", "low");
  const World w = build(map, smooth_params());
  ASSERT_EQ(w.curbs.size(), 2u);
  ASSERT_EQ(w.curb_kinds.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const Lanelet2LineString& way = map.lines.at(i == 0 ? 1 : 3);
    ASSERT_EQ(w.curbs[i].size(), way.points.size());
    for (size_t k = 0; k < way.points.size(); ++k) EXPECT_EQ(w.curbs[i][k], way.points[k].head<2>());
  }
  EXPECT_EQ(w.curb_kinds[0], "vertical");
  EXPECT_EQ(w.curb_kinds[1], "sloped");
  ASSERT_TRUE(w.surface);
  EXPECT_TRUE(w.bounds.contains(Eigen::Vector2d(30, 0)));
  EXPECT_GT(region::area(w.carriageway), kLength * 2 * kHalfWidth * 0.99);
}

TEST(Lanelet2World, LowCurbIsLowerThanHighCurb) {
  const World w = build(straight_road("curbstone", "high", "curbstone", "low"), smooth_params());
  RayScene scene(w.mesh);
  const auto high = down(scene, 20.2, kHalfWidth + 0.5), low = down(scene, 20.2, -kHalfWidth - 0.5);
  ASSERT_TRUE(high && low);
  const Lanelet2Standards de = lanelet2_standards("de");
  EXPECT_NEAR(high->first, de.curb_high, 0.005);
  EXPECT_NEAR(low->first, de.curb_low, 0.005);
  EXPECT_LT(low->first, high->first - 0.05);
  // The US standard's curbs are higher: AASHTO's 6 in and 4 in.
  Lanelet2WorldParams us = smooth_params();
  us.country = "us";
  const World wu = build(straight_road("curbstone", "high", "curbstone", "low"), us);
  EXPECT_NEAR(wu.raised_level({20.2, kHalfWidth + 0.5}), 0.1524, 0.005);
  EXPECT_NEAR(wu.raised_level({20.2, -kHalfWidth - 0.5}), 0.1016, 0.005);
}

// Merges the x-extents of paint triangles near a line y = y0 into intervals: the dashes.
std::vector<std::pair<double, double>> paint_runs(const TriangleMesh& mesh, double y0) {
  std::vector<std::pair<double, double>> spans;
  const MaterialId paint = material("lane_paint");
  for (size_t i = 0; i < mesh.triangle_count(); ++i) {
    if (mesh.materials[i] != paint) continue;
    double lo = 1e9, hi = -1e9, y = 0;
    for (uint32_t v : mesh.triangles[i]) {
      lo = std::min(lo, double(mesh.vertices[v].x())), hi = std::max(hi, double(mesh.vertices[v].x()));
      y += mesh.vertices[v].y() / 3.0;
    }
    if (std::abs(y - y0) < 0.5) spans.emplace_back(lo, hi);
  }
  std::sort(spans.begin(), spans.end());
  std::vector<std::pair<double, double>> runs;
  for (const auto& s : spans)
    if (!runs.empty() && s.first <= runs.back().second + 1e-3)
      runs.back().second = std::max(runs.back().second, s.second);
    else
      runs.push_back(s);
  return runs;
}

TEST(Lanelet2World, DashedLineHasTheStandardsDashAndGap) {
  const World w = build(straight_road("curbstone", "high", "curbstone", "high"), smooth_params());
  const Lanelet2Standards de = lanelet2_standards("de");
  const auto runs = paint_runs(w.mesh, 0);
  ASSERT_GE(runs.size(), 5u);
  for (size_t i = 0; i + 1 < runs.size(); ++i) {
    EXPECT_NEAR(runs[i].second - runs[i].first, de.dash, 0.01) << i;     // RMS: 3 m line
    EXPECT_NEAR(runs[i + 1].first - runs[i].second, de.gap, 0.01) << i;  // 6 m gap
  }
  // Its width: the Schmalstrich's 0.12 m, a few mm above the pavement.
  RayScene scene(w.mesh);
  const auto on = down(scene, runs[1].first + 1.0, 0.05), off = down(scene, runs[1].first + 1.0, 0.07);
  ASSERT_TRUE(on && off);
  EXPECT_EQ(on->second, material("lane_paint"));
  EXPECT_EQ(off->second, material("asphalt"));
  // Paint vertices at the line's edges (0.06 m off the crown line), a few mm above the pavement there.
  const double crown = de.cross_slope * (kHalfWidth - de.thin_width / 2);
  EXPECT_NEAR(on->first, crown + smooth_params().geometry.paint_height, 1e-3);
}

TEST(Lanelet2World, RoadBorderGivesNoStep) {
  Lanelet2BuildReport report;
  const World w = build(straight_road("curbstone", "high", "road_border", ""), smooth_params(), &report);
  RayScene scene(w.mesh);
  const auto inside = down(scene, 40.3, -kHalfWidth + 0.02), outside = down(scene, 40.3, -kHalfWidth - 0.02);
  ASSERT_TRUE(inside && outside);
  EXPECT_NEAR(inside->first, outside->first, 0.002);
  EXPECT_NEAR(w.raised_level({40.3, -kHalfWidth - 2.0}), 0.0, 0.002);
  EXPECT_EQ(report.road_borders, 1);
  EXPECT_EQ(report.curbstones_high, 1);
  ASSERT_EQ(w.curbs.size(), 1u);
}

TEST(Lanelet2World, MapWithoutCurbstonesBuildsAndWarns) {
  Lanelet2BuildReport report;
  const World w = build(straight_road("road_border", "", "line_thin", "solid"), smooth_params(), &report);
  EXPECT_TRUE(w.curbs.empty());
  EXPECT_GT(w.mesh.triangle_count(), 0u);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings[0].find("no curbstones"), std::string::npos);
  EXPECT_NE(report.summary().find("warning: the map has no curbstones"), std::string::npos);
}

Lanelet2Area rectangle_area(Lanelet2Id id, const std::string& subtype, double x0, double y0, double x1, double y1) {
  Lanelet2Area a;
  a.id = id;
  a.subtype = subtype;
  a.outer = {{{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}}};
  return a;
}

TEST(Lanelet2World, ParkingAreaFilledToTheOccupancy) {
  Lanelet2Map map = straight_road("curbstone", "high", "curbstone", "high");
  // 20 m along the road, 5 m deep: one row of 8 perpendicular stalls (EAR 05: 2.50 m x 5.00 m).
  map.areas.push_back(rectangle_area(50, "parking", 20, kHalfWidth + 0.5, 40, kHalfWidth + 5.5));
  Lanelet2WorldParams params = smooth_params();
  params.parking_occupancy = 1.0;
  Lanelet2BuildReport full, empty;
  const World w = build(map, params, &full);
  EXPECT_EQ(full.parking_areas, 1);
  EXPECT_EQ(full.parking_stalls, 8);
  EXPECT_EQ(full.parked_vehicles, 8);
  params.parking_occupancy = 0.0;
  const World w0 = build(map, params, &empty);
  EXPECT_EQ(empty.parking_stalls, 8);
  EXPECT_EQ(empty.parked_vehicles, 0);
  const TriangleMesh car = load_actor_mesh(test::data_path("assets/actors"), ActorType::car, test::materials());
  EXPECT_EQ(w.mesh.triangle_count() - w0.mesh.triangle_count(), 8 * car.triangle_count());
  // The default, Shoup's 85 %, of 8 stalls: 7 cars, the same ones for the same seed.
  params.parking_occupancy = Lanelet2WorldParams().parking_occupancy;
  Lanelet2BuildReport a, b;
  const World wa = build(map, params, &a), wb = build(map, params, &b);
  EXPECT_EQ(a.parked_vehicles, 7);
  EXPECT_EQ(wa.mesh.vertices, wb.mesh.vertices);
}

TEST(Lanelet2World, EverythingElseIsBuiltOrNamed) {
  Lanelet2Map map = straight_road("curbstone", "high", "curbstone", "high");
  map.lines[20] = line(20, "stop_line", "", {{50, -3.3, 0}, {50, -0.1, 0}});
  map.lines[21] = line(21, "keepout", "", along(10, 0, 5));
  map.lines[22] = line(22, "virtual", "", along(0, 0, 5));
  map.lines[23] = line(23, "wall", "", along(kHalfWidth + 20));
  map.lines[24] = line(24, "traffic_sign", "de205", {{10, kHalfWidth + 1, 0}, {10.6, kHalfWidth + 1, 0}});
  map.lines[25] = line(25, "line_thin", "solid_dashed", along(-1.75, 5, 25));
  map.areas.push_back(rectangle_area(60, "vegetation", 5, kHalfWidth + 3, 45, kHalfWidth + 15));
  map.areas.push_back(rectangle_area(61, "keepout", 5, -kHalfWidth - 9, 10, -kHalfWidth - 5));
  Lanelet2BuildReport r;
  const World w = build(map, smooth_params(), &r);
  EXPECT_EQ(r.stop_lines, 1);
  EXPECT_EQ(r.walls, 1);
  EXPECT_EQ(r.traffic_signs, 1);
  EXPECT_EQ(r.vegetation_areas, 1);
  EXPECT_GT(r.trees, 0);
  EXPECT_EQ(r.paint_lines["line_thin dashed"], 1);
  EXPECT_EQ(r.paint_lines["line_thin solid_dashed"], 1);
  EXPECT_EQ(r.not_built["keepout line"], 1);
  EXPECT_EQ(r.not_built["virtual: not drawn"], 1);
  EXPECT_EQ(r.not_built["keepout area"], 1);
  // The sign's plate is retro-reflective, at the standard's height.
  RayScene scene(w.mesh);
  RayHit hit;
  ASSERT_TRUE(scene.intersect({Eigen::Vector3f(10.3f, 0, 2.3f), Eigen::Vector3f(0, 1, 0)}, 0, 10, hit));
  EXPECT_EQ(hit.material, material("retro_reflector"));
  const std::string summary = r.summary();
  EXPECT_NE(summary.find("keepout area: 1"), std::string::npos) << summary;
}

TEST(Lanelet2World, KarlsruheCurbsAreTheFilesCurbstones) {
  const std::string path =
      std::string(LIDARLOOP_DATA_DIR) + "/../shared/data/maps/lanelet2/karlsruhe_mapping_example.osm";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not there";
  // Its speed (issue 35: under 20 s) is measured by `lidarloop world` in docs/lanelet2-worlds.md, not
  // here: a timed test fails on a loaded machine (it did, instrumented, beside other tests).
  const Lanelet2Map map = read_lanelet2(path);
  Lanelet2BuildReport report;
  const World w =
      build_lanelet2_world(map, Lanelet2WorldParams(), test::materials(), test::data_path("assets/actors"), &report);
  double ways = 0;
  int count = 0;
  for (const auto& [id, s] : map.lines)
    if (s.type == "curbstone") {
      ++count;
      Polyline2d flat;
      for (const auto& p : s.points) flat.push_back(p.head<2>());
      ways += polyline_length(flat);
    }
  double built = 0;
  for (const auto& c : w.curbs) built += polyline_length(c);
  EXPECT_EQ(count, 325);
  EXPECT_EQ(w.curbs.size(), 325u);
  EXPECT_NEAR(built, ways, 0.01 * ways);
  EXPECT_EQ(report.road_lanelets + report.cycle_tracks, 337 + 8 + 14);
  std::cout << report.summary() << w.mesh.triangle_count() << " triangles; " << w.bounds.sizes().transpose()
            << " m; carriageway " << region::area(w.carriageway) << " m2\n";
}

}  // namespace
}  // namespace lidarloop
