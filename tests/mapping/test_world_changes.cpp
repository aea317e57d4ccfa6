// A scenario's world_changes: today's world differs from the one the map was surveyed in. Read back
// from the meshes by ray casts, from today's scans, and from the intensity layer of the survey.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/input_error.hpp"
#include "common/yaml_reader.hpp"
#include "mapping/mapping_drive.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/ray_scene.hpp"
#include "sim/vehicle_model.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

// A 40 m two-lane road, dashed centre line and edge lines; a car parked on the verge beside it.
const char* kWorld = R"(name: changes
origin: {lat: 31.28, lon: 121.21}
road_defaults: {width: 8.0, lanes: 2, marking: dashed, edge_lines: true, sidewalk_width: 2, cross_slope: 0}
geometry: {roughness_class: none, sidewalk_cross_slope: 0}
roads:
  - {name: main, points: [[0, 0], [40, 0]]}
parked_vehicles:
  - {position: [20, 8.0], yaw_deg: 0, type: car}
)";
constexpr double kCarX = 20, kCarY = 8.0;

WorldDescription surveyed() { return parse_world_description(kWorld, "changes.yaml"); }

WorldDescription today(const std::string& changes) {
  const YamlReader y = YamlReader::from_string("world_changes:\n" + changes, "scenario.yaml");
  return apply_world_changes(surveyed(), y, y.root()["world_changes"]);
}

World build(const WorldDescription& d) { return build_world(d, test::materials(), test::data_path("assets/actors")); }

// What a ray straight down at (x, y) hits first.
RayHit look_down(const World& w, double x, double y) {
  constexpr float kAbove = 50;
  const RayScene scene(w.mesh);
  RayHit hit;
  EXPECT_TRUE(scene.intersect({{float(x), float(y), kAbove}, {0, 0, -1}}, 0, 2 * kAbove, hit));
  hit.range = kAbove - hit.range;  // now the height hit
  return hit;
}

TEST(WorldChanges, AParkedCarGoneSinceTheSurveyIsNotInTodaysWorld) {
  const RayHit then = look_down(build(surveyed()), kCarX, kCarY);
  const RayHit now = look_down(build(today("  parked_vehicles_gone: [[20.3, 8.2]]\n")), kCarX, kCarY);
  EXPECT_GT(then.range, 1.0);  // the car's roof
  EXPECT_LT(now.range, 0.3);   // the verge
}

TEST(WorldChanges, APaintStretchWornAwayOrRepaintedAside) {
  // The dashed centre line at y = 0 has dashes at x in [0, 3], [9, 12], ...; the edge line at y = -3.7.
  const MaterialId paint = test::materials().id("lane_paint", "test");
  const World base = build(surveyed());
  const World worn = build(today("  paint_worn: [{road: main, at: 10, length: 8}]\n"));
  const World moved = build(today("  paint_repainted: [{road: main, at: 30, length: 10, shift: 0.5}]\n"));
  EXPECT_EQ(look_down(base, 10, 0).material, paint);
  EXPECT_EQ(look_down(base, 10, -3.7).material, paint);
  EXPECT_NE(look_down(worn, 10, 0).material, paint);
  EXPECT_NE(look_down(worn, 10, -3.7).material, paint);
  EXPECT_EQ(look_down(worn, 2, -3.7).material, paint);  // outside the stretch: as it was
  // Repainted 0.5 m to the left from x = 25 to 35: the edge line is at y = -3.2 there.
  EXPECT_EQ(look_down(base, 30, -3.7).material, paint);
  EXPECT_NE(look_down(moved, 30, -3.7).material, paint);
  EXPECT_EQ(look_down(moved, 30, -3.2).material, paint);
}

TEST(WorldChanges, AConstructionZoneStandsConesAndBarriersOnTheClosedSide) {
  const World w = build(today("  construction: [{road: main, at: 20, length: 24, side: right}]\n"));
  const MaterialTable& m = test::materials();
  // The first cone stands at the stretch's start (x = 8), 0.3 m into the closed (right) half.
  const RayHit cone = look_down(w, 8.0, -0.3);
  EXPECT_EQ(cone.material, m.id("traffic_cone", "test"));
  EXPECT_NEAR(cone.range, 0.71, 0.02);  // MUTCD 6F.64: 28 in
  // A barrier down the middle of the closed lane (y = -2): 0.81 m of concrete.
  const RayHit barrier = look_down(w, 8.0 + 1.9, -2.0);
  EXPECT_EQ(barrier.material, m.id("curb_concrete", "test"));
  EXPECT_NEAR(barrier.range, 0.81, 0.01);
  EXPECT_LT(look_down(w, 8.0, 2.0).range, 0.05);  // the open lane is clear
}

// The zone's curb edits since the survey, on the closed (right) side from x = 8 to 32: a temporary
// kerb 1 m into the road (its face at y = -3), and the old curb at y = -4 taken out (a flush cut). The
// survey's world has neither; today's world has both, in its meshes and in its curb lines.
TEST(WorldChanges, AConstructionZoneMovesTheClosedSidesCurb) {
  const World then = build(surveyed());
  const World now = build(
      today("  construction: [{road: main, at: 20, length: 24, side: right, curb_removed: true, curb_shift: 1.0}]\n"));
  const MaterialId concrete = test::materials().id("curb_concrete", "test");
  // The kerb block behind the new face: as high as the road's curb (0.15 m), where the survey saw road.
  EXPECT_LT(look_down(then, 20, -3.15).range, 0.02);
  const RayHit kerb = look_down(now, 20, -3.15);
  EXPECT_EQ(kerb.material, concrete);
  EXPECT_NEAR(kerb.range, 0.15, 0.01);
  EXPECT_LT(look_down(now, 5, -3.15).range, 0.02);  // before the zone: road as it was
  // Curb lines: today a vertical one along y = -3 over the zone, and the old curb flush over the zone.
  auto along = [](const World& w, double y, const std::string& kind) {
    double covered = 0;  // m of x in [8, 32] that a line of this kind runs along y
    for (size_t i = 0; i < w.curbs.size(); ++i) {
      if (w.curb_kinds[i] != kind) continue;
      const Polyline2d& l = w.curbs[i];
      for (size_t k = 1; k < l.size(); ++k) {
        const Eigen::Vector2d &a = l[k - 1], &b = l[k];
        if (std::abs(a.y() - y) < 0.05 && std::abs(b.y() - y) < 0.05)
          covered += std::max(0.0, std::min({std::max(a.x(), b.x()), 32.0}) - std::max({std::min(a.x(), b.x()), 8.0}));
      }
    }
    return covered;
  };
  EXPECT_EQ(along(then, -3.0, "vertical"), 0.0);
  EXPECT_NEAR(along(now, -3.0, "vertical"), 24.0, 0.1);
  EXPECT_EQ(along(then, -4.0, "flush"), 0.0);
  EXPECT_GT(along(now, -4.0, "flush"), 23.0);
  RecordProperty("flush_m", std::to_string(along(now, -4.0, "flush")));
}

TEST(WorldChanges, AHedgeGrownSinceTheSurveyLeansOverTheCurbToday) {
  const World then = build(surveyed());
  const World now =
      build(today("  vegetation_grown: [{road: main, at: 30, length: 10, side: right, overhang: 0.3}]\n"));
  const MaterialId leaves = test::materials().id("vegetation", "test");
  EXPECT_NE(look_down(then, 30, -4.0).material, leaves);
  EXPECT_EQ(look_down(now, 30, -4.0).material, leaves);  // over the right curb line
  EXPECT_NE(look_down(now, 20, -4.0).material, leaves);  // outside the stretch
}

TEST(WorldChanges, MistakesAreErrorsAtTheirLine) {
  auto message = [](const std::string& changes) {
    try {
      today(changes);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("  parked_vehicles_gone: [[5, 5]]\n").find("scenario.yaml:2:"), std::string::npos);
  EXPECT_NE(message("  parked_vehicles_gone: [[5, 5]]\n").find("no parked vehicle"), std::string::npos);
  EXPECT_NE(message("  paint_worn: [{road: side, at: 10}]\n").find("unknown road 'side'"), std::string::npos);
  EXPECT_NE(message("  painted_worn: []\n").find("did you mean 'paint_worn'"), std::string::npos);
  EXPECT_NE(message("  construction: [{road: main, at: 20, side: both}]\n").find("one side"), std::string::npos);
  // A kerb shifted past the closed lanes' outer half would stand in the barriers (8 m road: at most 1.5 m).
  EXPECT_NE(message("  construction: [{road: main, at: 20, curb_shift: 1.6}]\n").find("curb_shift"), std::string::npos);
}

// The map is surveyed with the car parked; today it is gone. Its wheels and sills (below the mapping
// drive's 0.5 m) leave mixed bright and dark returns in the cells around it: their intensity variance
// is far above the same cells' in a survey without it. Today's scans see nothing there.
TEST(WorldChanges, ACarParkedOnlyAtSurveyTimeLeavesItsTraceInTheMapAndNotInTodaysScans) {
  const WorldDescription then = surveyed();
  const WorldDescription now = today("  parked_vehicles_gone: [[20, 8]]\n");
  const World world_then = build(then), world_now = build(now);
  MappingOptions o;
  o.survey_error.sigma_xy_m = o.survey_error.heading_sigma_rad = 0;
  const auto map_then =
      run_mapping_drive(then, world_then, test::materials(), test::data_path("assets/actors"), o, "a");
  const auto map_now = run_mapping_drive(now, world_now, test::materials(), test::data_path("assets/actors"), o, "b");
  // Around the car (its footprint, about 4.5 m x 1.8 m, and a margin): cells whose intensity
  // variance at least doubled. Far from it (x < 8 m) the two surveys are the same cell for cell.
  const double res = map_then.header().resolution_m;
  int near = 0, raised = 0, far = 0, far_same = 0;
  for (double x = 0.1; x < 40; x += res)
    for (double y = kCarY - 1.5; y < kCarY + 1.5; y += res) {
      const auto a = map_then.cell({x, y}), b = map_now.cell({x, y});
      if (!a || !b || a->count < 2 || b->count < 2) continue;
      if (std::abs(x - kCarX) < 3) {
        ++near;
        raised += a->variance() > 2 * b->variance();
      } else if (std::abs(x - kCarX) > 12) {
        ++far;
        far_same += a->count == b->count && a->mean == b->mean && a->m2 == b->m2;
      }
    }
  std::cout << "[ figures  ] around the car " << raised << " of " << near << " cells at least doubled their variance; "
            << far_same << " of " << far << " cells far from it the same\n";
  ASSERT_GT(near, 50);
  EXPECT_GE(raised, 20);  // without the car, none could: the surveys differ only where it stood
  EXPECT_EQ(far_same, far);

  // Today's scan from the road beside it: no return above the verge where the car stood.
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const LidarScanner scanner(config, test::materials());
  const Eigen::Isometry3d vehicle = Eigen::Translation3d(kCarX - 8, -2, 0) * Eigen::Isometry3d::Identity();
  auto returns_on_car = [&](const World& w) {
    RayScene scene(w.mesh);
    const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, 1);
    int n = 0;
    for (const auto& p : cloud.points) {
      const Eigen::Vector3d q = vehicle * config.mount() * Eigen::Vector3d(p.x, p.y, p.z);
      n += std::abs(q.x() - kCarX) < 2.5 && std::abs(q.y() - kCarY) < 1.1 && q.z() > 0.4;
    }
    return n;
  };
  EXPECT_GT(returns_on_car(world_then), 100);
  EXPECT_EQ(returns_on_car(world_now), 0);
}

}  // namespace
}  // namespace lidarloop
