// A world from an OpenDRIVE map (sim/opendrive_world.hpp), on small maps written inline whose geometry
// is known (a straight town street along +x), the project's small town, and the real maps from
// ../shared (esmini's fabriksgatan, CARLA's Town01) when they are there.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/actor_assets.hpp"
#include "sim/lane_graph.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/polyline.hpp"
#include "sim/ray_scene.hpp"
#include "test_support.hpp"
#include "tests/sim/opendrive_test_maps.hpp"

namespace lidarloop {
namespace {

using namespace odr_test;

const std::string kShared = std::string(LIDARLOOP_DATA_DIR) + "/../shared/data/maps/opendrive/";

MaterialId material(const std::string& name) { return test::materials().id(name, "test"); }

OdrWorldParams smooth_params() {
  OdrWorldParams p;
  p.geometry.roughness_class = '-';  // a pavement as smooth as a drawing: heights are exact
  p.geometry.margin = 10;
  return p;
}

World build(const OdrMap& map, const OdrWorldParams& params, OdrBuildReport* report = nullptr) {
  return build_opendrive_world(map, params, test::materials(), test::data_path("assets/actors"), report);
}

World build_text(const std::string& body, const OdrWorldParams& params, OdrBuildReport* report = nullptr) {
  return build(parse_opendrive(map_text(body), "test.xodr"), params, report);
}

// Height of the first surface a ray straight down meets at (x, y), and its material.
std::optional<std::pair<double, MaterialId>> down(const RayScene& scene, double x, double y) {
  RayHit hit;
  if (!scene.intersect({Eigen::Vector3f(float(x), float(y), 10.f), Eigen::Vector3f(0, 0, -1)}, 0, 20, hit))
    return std::nullopt;
  return std::make_pair(10.0 - hit.range, hit.material);
}

TEST(OpenDriveWorld, TownStreetHasPavementCurbAndRaisedSidewalk) {
  OdrBuildReport report;
  const World w = build_text(road("1", 60, "<line/>", town_lanes()), smooth_params(), &report);
  RayScene scene(w.mesh);
  for (const double y : {-3.0, -1.0, 2.0, 3.7}) {
    const auto hit = down(scene, 30.3, y);
    ASSERT_TRUE(hit) << y;
    EXPECT_NEAR(hit->first, 0, 1e-4) << y;
  }
  EXPECT_EQ(down(scene, 30.3, -2.0)->second, material("asphalt"));
  const double edge = 3.5 + 0.3;  // the shoulder's outer edge, where the curb mark is
  for (const double side : {1.0, -1.0}) {
    // A horizontal ray across the road below the sidewalk's level meets the curb face at the edge.
    RayHit hit;
    ASSERT_TRUE(scene.intersect({Eigen::Vector3f(31.1f, float(side * 3.0), 0.06f), Eigen::Vector3f(0, float(side), 0)},
                                0, 10, hit));
    EXPECT_NEAR(3.0 + hit.range, edge, 0.01);
    EXPECT_EQ(hit.material, material("curb_concrete"));
    // The sidewalk behind it at the default height (no height in the map), and the ground beyond at its level.
    const auto walk = down(scene, 31.1, side * (edge + 1.0));
    ASSERT_TRUE(walk);
    EXPECT_NEAR(walk->first, OdrWorldParams().sidewalk_height, 1e-4);
    EXPECT_EQ(walk->second, material("sidewalk"));
    const auto verge = down(scene, 31.1, side * (edge + 4.0));
    ASSERT_TRUE(verge);
    EXPECT_NEAR(verge->first, OdrWorldParams().sidewalk_height, 1e-3);
    EXPECT_EQ(verge->second, material("grass"));
  }
  EXPECT_NEAR(w.ground()({30, -1}), 0, 1e-9);
  EXPECT_NEAR(w.ground()({30, -5}), 0.12, 1e-6);
  // The curb lines: along both edges, the length of the road.
  ASSERT_EQ(w.curbs.size(), 2u);
  for (const auto& c : w.curbs) {
    EXPECT_NEAR(polyline_length(c), 60, 0.01);
    for (const auto& p : c) EXPECT_NEAR(std::abs(p.y()), edge, 1e-3);
  }
  EXPECT_EQ(report.raised_by_default, 2);
  EXPECT_EQ(report.curb_marks, 2);
  EXPECT_EQ(report.curb_lines, 2);
  EXPECT_EQ(report.lanes.at("driving"), 2);
  EXPECT_EQ(report.lanes.at("sidewalk"), 2);
}

TEST(OpenDriveWorld, LaneHeightsFromTheMapMakeTheCurb) {
  // As esmini draws fabriksgatan: a border lane at 0, then a sidewalk 0.12 m high at its inner edge and
  // 0.14 m at its outer; no curb marks.
  const std::string walk =
      "          <lane id=\"-3\" type=\"sidewalk\"><width sOffset=\"0\" a=\"2\"/>"
      "<height sOffset=\"0\" inner=\"0.12\" outer=\"0.14\"/></lane>\n";
  const std::string lanes = section(lane(1, "driving", 3.5), lane(-1, "driving", 3.5) + lane(-2, "border", 0.3) + walk);
  OdrBuildReport report;
  const World w = build_text(road("1", 40, "<line/>", lanes), smooth_params(), &report);
  RayScene scene(w.mesh);
  EXPECT_NEAR(down(scene, 20.2, -3.8 - 0.01)->first, 0.1201, 1e-4);
  EXPECT_NEAR(down(scene, 20.2, -3.8 - 1.0)->first, 0.13, 1e-4);
  EXPECT_NEAR(down(scene, 20.2, -3.6)->first, 0, 1e-4);
  EXPECT_EQ(report.raised_by_default, 0);
  // One curb on the right, at the sidewalk's inner edge; none on the left (a driving lane's edge with
  // the ground beside it at the road's level).
  ASSERT_EQ(w.curbs.size(), 1u);
  for (const auto& p : w.curbs[0]) EXPECT_NEAR(p.y(), -3.8, 1e-3);
}

TEST(OpenDriveWorld, BrokenCentreLineHasItsPattern) {
  // The centre lane's mark: broken, RMS-1's 3 m dashes with 6 m gaps from s = 0; an explicit pattern
  // on the right lane's outer edge: 1 m lines with 1 m spaces.
  const std::string mark =
      "<roadMark sOffset=\"0\" type=\"broken\" width=\"0.15\"><type name=\"p\">"
      "<line length=\"1\" space=\"1\" tOffset=\"0\" sOffset=\"0\" width=\"0.15\"/></type></roadMark>\n";
  OdrBuildReport report;
  const World w = build_text(road("1", 40, "<line/>", section(lane(1, "driving", 3.5), lane(-1, "driving", 3.5, mark))),
                             smooth_params(), &report);
  RayScene scene(w.mesh);
  for (const double x : {0.5, 2.5, 9.5, 11.5}) EXPECT_EQ(down(scene, x, 0)->second, material("lane_paint")) << x;
  for (const double x : {3.5, 5.0, 8.5, 12.5}) EXPECT_EQ(down(scene, x, 0)->second, material("asphalt")) << x;
  EXPECT_NEAR(down(scene, 1.0, 0)->first, OdrWorldParams().geometry.paint_height, 1e-4);
  for (const double x : {0.5, 2.5, 4.5}) EXPECT_EQ(down(scene, x, -3.5)->second, material("lane_paint")) << x;
  // In the spaces: the lane's asphalt, 3 cm inside the lane (the line's centre is the lane's edge, where
  // the asphalt and the ground beside it meet in one plane, and either may answer a ray on it).
  for (const double x : {1.5, 3.5}) EXPECT_EQ(down(scene, x, -3.47)->second, material("asphalt")) << x;
  // Width: 0.12 m from the mark, so 0.05 m off the line is paint and 0.08 m is not.
  EXPECT_EQ(down(scene, 1.0, 0.05)->second, material("lane_paint"));
  EXPECT_EQ(down(scene, 1.0, 0.08)->second, material("asphalt"));
  EXPECT_EQ(report.paint.at("broken white"), 1);
  EXPECT_EQ(report.paint.at("broken"), 1);
}

TEST(OpenDriveWorld, ParkingLaneFilledToTheOccupancy) {
  // A 2.2 m parking lane along 40 m: 7 parallel stalls of EAR 05's 5.70 m.
  const std::string lanes = section(lane(1, "driving", 3.5), lane(-1, "driving", 3.5) + lane(-2, "parking", 2.2));
  OdrWorldParams params = smooth_params();
  params.parking_occupancy = 1.0;
  OdrBuildReport full, none;
  const World w = build_text(road("1", 40, "<line/>", lanes), params, &full);
  params.parking_occupancy = 0.0;
  const World w0 = build_text(road("1", 40, "<line/>", lanes), params, &none);
  EXPECT_EQ(full.parking_stalls, 7);
  EXPECT_EQ(full.parked_vehicles, 7);
  EXPECT_EQ(none.parked_vehicles, 0);
  const TriangleMesh car = load_actor_mesh(test::data_path("assets/actors"), ActorType::car, test::materials());
  EXPECT_EQ(w.mesh.triangle_count() - w0.mesh.triangle_count(), 7 * car.triangle_count());
  // A car stands in the lane: a ray down at its middle meets the car's roof, well above the road.
  RayScene scene(w.mesh);
  EXPECT_GT(down(scene, 20, -4.6)->first, 1.0);
}

TEST(OpenDriveWorld, EverythingElseIsBuiltOrNamed) {
  // The project's small town: a junction's connecting road (its marks not painted), a crosswalk, a
  // pole, a parking space, a biking lane; plus a lane of type none and a signal read but not built.
  OdrMap map = read_opendrive(test::data_path("tests/data/opendrive/small_town.xodr"));
  OdrLane none;
  none.id = -5;
  none.type = "none";
  none.width.push_back({0, 1, 0, 0, 0});
  map.roads[0].sections[0].right.push_back(none);
  map.roads[0].signals = 2;
  OdrBuildReport report;
  const World w = build(map, smooth_params(), &report);
  EXPECT_EQ(report.roads, 2);
  EXPECT_EQ(report.junction_roads, 1);
  EXPECT_EQ(report.junctions, 1);
  EXPECT_EQ(report.crosswalks, 1);
  EXPECT_EQ(report.crosswalk_stripes, 7);  // 7 m across: 7 stripes of 0.5 m with 0.5 m gaps
  EXPECT_EQ(report.poles, 1);
  EXPECT_GE(report.parking_stalls, 1 + 10);  // the parking space and the parking lane's stalls
  EXPECT_EQ(report.not_built.at("lane of type none"), 1);
  EXPECT_EQ(report.not_built.at("signal (rules, no geometry)"), 2);
  EXPECT_GE(report.curb_lines, 2);
  EXPECT_EQ(report.lanes.at("biking"), 1);
  EXPECT_EQ(report.paint.at("solid solid yellow"), 1);
  const std::string summary = report.summary();
  EXPECT_NE(summary.find("not built: lane of type none: 1;"), std::string::npos) << summary;
  // The crosswalk's stripes, across the road at s = 10 (a straight stretch): paint on the stripes.
  RayScene scene(w.mesh);
  EXPECT_EQ(down(scene, 10, -3.0)->second, material("crosswalk_paint"));  // stripes centred 1 m apart from t = -3
  EXPECT_EQ(down(scene, 10, -2.5)->second, material("asphalt"));
}

TEST(OpenDriveWorld, FabriksgatanCurbsStandAtTheFilesHeight) {
  if (!std::filesystem::exists(kShared + "fabriksgatan.xodr")) GTEST_SKIP() << kShared << " not there";
  OdrBuildReport report;
  const World w = build(read_opendrive(kShared + "fabriksgatan.xodr"), smooth_params(), &report);
  ASSERT_GT(w.curbs.size(), 3u);
  RayScene scene(w.mesh);
  // Across every curb line, every 5 m: the carriageway just in front, the sidewalk 0.12 m higher behind.
  int checked = 0;
  for (const auto& c : w.curbs) {
    const double length = polyline_length(c);
    for (double at = 1; at < length - 1; at += 5) {
      const PolylineSample q = sample_polyline(c, at);
      const Eigen::Vector2d out(q.tangent.y(), -q.tangent.x());  // the carriageway is on the line's left
      const auto low = down(scene, (q.point - out * 0.1).x(), (q.point - out * 0.1).y());
      const auto high = down(scene, (q.point + out * 0.1).x(), (q.point + out * 0.1).y());
      ASSERT_TRUE(low && high);
      if (high->second != material("sidewalk")) continue;  // a corner: the ground behind is blended
      EXPECT_NEAR(high->first - low->first, 0.12, 0.005) << q.point.transpose();
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

// What the localizer is given: a scan. A noiseless HDL-32E on the carriageway, 2.5 m from the middle of
// each of fabriksgatan's longest curb lines, heading along it: the points on the sidewalk just behind the
// curb stand the file's 0.12 m above those on the carriageway just in front.
TEST(OpenDriveWorld, FabriksgatanScanShowsItsSidewalkCurbsAtTheFilesHeight) {
  if (!std::filesystem::exists(kShared + "fabriksgatan.xodr")) GTEST_SKIP() << kShared << " not there";
  const World w = build(read_opendrive(kShared + "fabriksgatan.xodr"), smooth_params());
  std::vector<const Polyline2d*> lines;
  for (const auto& c : w.curbs) lines.push_back(&c);
  std::sort(lines.begin(), lines.end(),
            [](const Polyline2d* a, const Polyline2d* b) { return polyline_length(*a) > polyline_length(*b); });
  ASSERT_GE(lines.size(), 2u);
  RayScene scene(w.mesh);
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const LidarScanner scanner(config, test::materials());
  for (size_t k = 0; k < 2; ++k) {
    const Polyline2d& curb = *lines[k];
    const PolylineSample q = sample_polyline(curb, polyline_length(curb) / 2);
    const Eigen::Vector2d out(q.tangent.y(), -q.tangent.x());  // towards the sidewalk
    const Eigen::Vector2d at = q.point - 2.5 * out;
    const auto ground = down(scene, at.x(), at.y());
    ASSERT_TRUE(ground && ground->second != material("sidewalk")) << at.transpose();
    const Eigen::Isometry3d vehicle =
        Eigen::Translation3d(at.x(), at.y(), ground->first) *
        Eigen::AngleAxisd(std::atan2(q.tangent.y(), q.tangent.x()), Eigen::Vector3d::UnitZ());
    const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, 1);
    const Eigen::Isometry3d sensor = vehicle * config.mount();
    std::vector<double> road, sidewalk;
    for (const auto& p : cloud.points) {
      const Eigen::Vector3d x = sensor * test::fired_point(p, config);
      const Eigen::Vector2d d = x.head<2>() - q.point;
      if (std::abs(d.dot(q.tangent)) > 4 || x.z() > ground->first + 0.5) continue;  // this stretch, the ground
      const double across = d.dot(out);
      if (across > -1.5 && across < -0.3) road.push_back(x.z());
      if (across > 0.1 && across < 0.8) sidewalk.push_back(x.z());
    }
    ASSERT_GT(road.size(), 30u) << "curb " << k;
    ASSERT_GT(sidewalk.size(), 30u) << "curb " << k;
    std::sort(road.begin(), road.end());
    std::sort(sidewalk.begin(), sidewalk.end());
    EXPECT_NEAR(sidewalk[sidewalk.size() / 2] - road[road.size() / 2], 0.12, 0.01) << "curb " << k;
  }
}

TEST(OpenDriveWorld, Town01BuildsWithJunctionsAndSidewalks) {
  if (!std::filesystem::exists(kShared + "Town01.xodr")) GTEST_SKIP() << kShared << " not there";
  OdrBuildReport report;
  const World w = build(read_opendrive(kShared + "Town01.xodr"), smooth_params(), &report);
  EXPECT_EQ(report.junctions, 12);
  EXPECT_EQ(report.lanes.at("sidewalk"), 52);
  EXPECT_GE(report.curb_lines, 8);  // the blocks' rings and the town's outer edge
  EXPECT_GT(report.curb_length_m, 5000);
  EXPECT_TRUE(report.warnings.empty()) << report.summary();
}

}  // namespace
}  // namespace lidarloop

namespace lidarloop {
namespace {

TEST(OpenDriveWorld, WorldFileNamesTheMapAndItsParameters) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "lidarloop_opendrive_world_test";
  std::filesystem::create_directories(dir);
  const std::string map = test::data_path("tests/data/opendrive/small_town.xodr");
  const std::string yaml = "name: small_town\nopendrive:\n  file: " + map +
                           "\n  sidewalk_height: 0.15\n  parking_occupancy: 1\n  paint_junctions: true\n";
  const WorldDescription d = parse_world_description(yaml, (dir / "world.yaml").string());
  ASSERT_TRUE(d.opendrive);
  EXPECT_DOUBLE_EQ(d.opendrive->params.sidewalk_height, 0.15);
  EXPECT_DOUBLE_EQ(d.opendrive->params.parking_occupancy, 1.0);
  EXPECT_TRUE(d.opendrive->params.paint_junctions);
  EXPECT_DOUBLE_EQ(d.origin.lat_deg, 48.78);  // the map's geoReference
  const World w = build_world(d, test::materials(), test::data_path("assets/actors"));
  EXPECT_FALSE(w.curbs.empty());
  EXPECT_NE(w.import_report.find("parking:"), std::string::npos);
  // Unknown keys and a world with both kinds of map are refused, naming the world file.
  for (const std::string& bad : {"name: x\nopendrive:\n  file: " + map + "\n  curb_hieght: 0.1\n",
                                 "name: x\nopendrive: {file: " + map + "}\nroads: []\n",
                                 std::string("name: x\nopendrive: {file: missing.xodr}\n")}) {
    try {
      parse_world_description(bad, (dir / "world.yaml").string());
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("world.yaml:"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace lidarloop

// The routing graph (sim/opendrive_lane_graph.hpp) on the project's small town and on Town01.
namespace lidarloop {
namespace {

TEST(OpenDriveLaneGraph, LanesFollowThroughTheJunctionAndRoutesAreChecked) {
  const OdrMap map = read_opendrive(test::data_path("tests/data/opendrive/small_town.xodr"));
  const OdrLaneGraph g = build_opendrive_lane_graph(map);
  // Road 1's right lane, the connecting road's lane, road 3's right lane: one after the other.
  const std::vector<LaneGraphNodeId> route = route_from_opendrive_lanes(g, {{"1", -1}, {"2", -1}, {"3", -1}});
  ASSERT_EQ(route.size(), 3u);
  const Polyline2d line = route_centreline(g.graph, route);
  EXPECT_NEAR(polyline_length(line), 80 + 20 + 40, 1.5);  // the paramPoly3 is a little longer than its p range
  // Lane 1 of road 1 drives against s: its centreline starts at the road's end.
  const LaneGraphNode& left = g.graph.nodes[size_t(g.nodes_of.at({"1", 1}).front())];
  EXPECT_GT(left.centreline.front().x(), 70);
  // The shortest route from road 1 to road 3 goes the same way.
  const std::vector<LaneGraphNodeId> shortest = shortest_route(g.graph, {5, -1.75}, {119.7, 27.3});
  EXPECT_EQ(shortest.front(), route.front());
  EXPECT_EQ(shortest.back(), route.back());
  for (const auto& [lanes, message] : std::vector<std::pair<std::vector<OdrLaneRef>, std::string>>{
           {{{"1", -1}, {"3", 1}}, "lane [3, 1] does not follow lane [1, -1]"},
           {{{"1", -2}}, "lane [1, -2] is not a driving lane of the map"},
           {{{"9", -1}}, "lane [9, -1] is not a driving lane"}}) {
    try {
      route_from_opendrive_lanes(g, lanes);
      ADD_FAILURE() << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(OpenDriveLaneGraph, LeftHandTrafficDrivesTheLeftLanesAlongS) {
  // A 50 m street along +x with two lanes each way, rule="LHT": lanes 1 and 2 are driven along s
  // (towards +x), with the kerbside lane 2 on their left; lanes -1 and -2 against it.
  const std::string lanes =
      section(lane(1, "driving", 3.5) + lane(2, "driving", 3.5), lane(-1, "driving", 3.5) + lane(-2, "driving", 3.5));
  std::string text = map_text(road("1", 50, "<line/>", lanes));
  const std::string plain = "<road id=\"1\"";
  text.replace(text.find(plain), plain.size(), "<road rule=\"LHT\" id=\"1\"");
  const OdrMap map = parse_opendrive(text, "lht.xodr");
  ASSERT_TRUE(map.roads[0].left_hand_traffic);
  const OdrLaneGraph g = build_opendrive_lane_graph(map);
  auto node = [&](int id) -> const LaneGraphNode& { return g.graph.nodes[size_t(g.nodes_of.at({"1", id}).front())]; };
  EXPECT_LT(node(1).centreline.front().x(), 1);
  EXPECT_GT(node(1).centreline.back().x(), 49);
  EXPECT_NEAR(node(1).centreline.front().y(), 1.75, 1e-9);
  EXPECT_NEAR(node(1).left_bound.front().y(), 3.5, 1e-9);  // the outer edge is on the left
  EXPECT_NEAR(node(1).right_bound.front().y(), 0, 1e-9);
  EXPECT_GT(node(-1).centreline.front().x(), 49);
  EXPECT_NEAR(node(-1).left_bound.front().y(), -3.5, 1e-9);
  ASSERT_TRUE(node(1).left.has_value());
  EXPECT_EQ(*node(1).left, g.nodes_of.at({"1", 2}).front());
  EXPECT_FALSE(node(1).right.has_value());  // across the centre line: the other way
  ASSERT_TRUE(node(-1).left.has_value());
  EXPECT_EQ(*node(-1).left, g.nodes_of.at({"1", -2}).front());
  std::string bad = text;
  bad.replace(bad.find("LHT"), 3, "XYZ");
  try {
    parse_opendrive(bad, "lht.xodr");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lht.xodr:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rule 'XYZ' is neither RHT nor LHT"), std::string::npos) << e.what();
  }
}

TEST(OpenDriveLaneGraph, LaneChangeFollowsTheMarksLaneChangeOverItsType) {
  // Two lanes along s; between them lane -1's solid mark with laneChange="increase": a car may move from
  // lane -2 to lane -1 (towards the larger id), not back. Without laneChange, solid forbids both.
  auto graph_with = [](const std::string& lane_change) {
    const std::string mark = "            <roadMark sOffset=\"0\" type=\"solid\" width=\"0.12\"" + lane_change + "/>\n";
    return build_opendrive_lane_graph(parse_opendrive(
        map_text(road("1", 50, "<line/>", section("", lane(-1, "driving", 3.5, mark) + lane(-2, "driving", 3.5)))),
        "t.xodr"));
  };
  const OdrLaneGraph g = graph_with(" laneChange=\"increase\"");
  const LaneGraphNode& inner = g.graph.nodes[size_t(g.nodes_of.at({"1", -1}).front())];
  const LaneGraphNode& outer = g.graph.nodes[size_t(g.nodes_of.at({"1", -2}).front())];
  ASSERT_TRUE(inner.right && outer.left);
  EXPECT_FALSE(inner.can_change_right);
  EXPECT_TRUE(outer.can_change_left);
  const OdrLaneGraph solid = graph_with("");
  EXPECT_FALSE(solid.graph.nodes[size_t(solid.nodes_of.at({"1", -2}).front())].can_change_left);
}

TEST(OpenDriveLaneGraph, Town01IsOneNetwork) {
  if (!std::filesystem::exists(kShared + "Town01.xodr")) GTEST_SKIP() << kShared << " not there";
  const OdrMap map = read_opendrive(kShared + "Town01.xodr");
  const OdrLaneGraph g = build_opendrive_lane_graph(map);
  // Every lane has a way on (the town has no dead ends), and the covering routes drive every node.
  for (const auto& n : g.graph.nodes)
    EXPECT_FALSE(n.successors.empty()) << g.lane_of[size_t(n.lanelet)].first << " "
                                       << g.lane_of[size_t(n.lanelet)].second;
  size_t covered = 0;
  for (const auto& r : covering_routes(g.graph)) covered += r.size();
  EXPECT_GE(covered, g.graph.nodes.size());
  // Across the town through junctions, both ways.
  EXPECT_GT(polyline_length(route_centreline(g.graph, shortest_route(g.graph, {120, -2}, {330, -320}))), 400);
  EXPECT_GT(polyline_length(route_centreline(g.graph, shortest_route(g.graph, {330, -320}, {120, -2}))), 400);
}

}  // namespace
}  // namespace lidarloop
