// Reading Lanelet2 maps (sim/lanelet2_file.hpp): small maps of the project's own with known geometry,
// written inline or under tests/data/lanelet2/, each bad input's one-line message, and the real
// Karlsruhe example map from ../shared when it is there.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <GeographicLib/Constants.hpp>
#include <GeographicLib/MGRS.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include "common/geodetic.hpp"
#include "common/input_error.hpp"
#include "sim/lanelet2_file.hpp"

namespace lidarloop {
namespace {

const Geodetic kOrigin{49.0, 8.4, 0};
const std::string kData = std::string(LIDARLOOP_DATA_DIR) + "/tests/data/lanelet2/";

// ---- Writing small maps ----

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string tags_xml(const std::map<std::string, std::string>& tags) {
  std::string out;
  for (const auto& [k, v] : tags) out += "    <tag k=\"" + k + "\" v=\"" + v + "\"/>\n";
  return out;
}

// A node at local metres (x east, y north) about kOrigin, written as WGS-84 lat / lon (1e-11 degrees:
// about a micrometre).
std::string node_at(int id, double x, double y) {
  const Geodetic g = LocalFrame(kOrigin).to_geodetic({x, y});
  return "  <node id=\"" + std::to_string(id) + "\" lat=\"" + fixed(g.lat_deg, 11) + "\" lon=\"" +
         fixed(g.lon_deg, 11) + "\"/>\n";
}

std::string way(int id, std::initializer_list<int> nodes, const std::map<std::string, std::string>& tags = {}) {
  std::string out = "  <way id=\"" + std::to_string(id) + "\">\n";
  for (const int n : nodes) out += "    <nd ref=\"" + std::to_string(n) + "\"/>\n";
  return out + tags_xml(tags) + "  </way>\n";
}

struct Member {
  std::string type;
  int ref;
  std::string role;
};

std::string relation(int id, const std::vector<Member>& members, const std::map<std::string, std::string>& tags) {
  std::string out = "  <relation id=\"" + std::to_string(id) + "\">\n";
  for (const auto& m : members)
    out += "    <member type=\"" + m.type + "\" ref=\"" + std::to_string(m.ref) + "\" role=\"" + m.role + "\"/>\n";
  return out + tags_xml(tags) + "  </relation>\n";
}

// Autoware's way: <osm> without a version attribute.
std::string osm(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<osm generator=\"test\">\n" + body + "</osm>\n";
}

const std::map<std::string, std::string> kRoad{
    {"type", "lanelet"}, {"subtype", "road"}, {"location", "urban"}, {"region", "DE"}};

// One straight lanelet `width` wide and 50 m long, pointing north, centred on x = 0, with the nodes
// 1, 2 (left bound, way 10) and 3, 4 (right bound, way 11), plus `extra` inside <osm>.
std::string straight(double width = 3.5, const std::string& extra = "") {
  return osm(node_at(1, -width / 2, 0) + node_at(2, -width / 2, 50) + node_at(3, width / 2, 0) +
             node_at(4, width / 2, 50) + way(10, {1, 2}, {{"type", "line_thin"}, {"subtype", "solid"}}) +
             way(11, {3, 4}, {{"type", "curbstone"}, {"subtype", "high"}}) +
             relation(100, {{"way", 10, "left"}, {"way", 11, "right"}}, kRoad) + extra);
}

Lanelet2ReadOptions at_origin() {
  Lanelet2ReadOptions options;
  options.origin = kOrigin;
  return options;
}

// ---- Checking errors ----

// Reading must throw an InputError whose one line contains every fragment.
void expect_error(const std::function<void()>& read, std::initializer_list<std::string> fragments) {
  try {
    read();
    ADD_FAILURE() << "no error; expected one containing '" << *fragments.begin() << "'";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const auto& f : fragments)
      EXPECT_NE(message.find(f), std::string::npos) << "'" << f << "' not in: " << message;
  }
}

void expect_parse_error(const std::string& xml, std::initializer_list<std::string> fragments) {
  expect_error([&] { parse_lanelet2(xml, "bad.osm"); }, fragments);
}

// ---- Temporary folders for maps with a projector file beside them ----

class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("lanelet2_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return (path_ / name).string();
  }

 private:
  std::filesystem::path path_;
};

// The straight lanelet's four corners in local metres about kOrigin.
const std::vector<Eigen::Vector2d> kCorners{{-1.75, 0}, {-1.75, 50}, {1.75, 0}, {1.75, 50}};

// The straight lanelet written with local_x / local_y tags (and a nominal lat / lon of 0, 0 that the
// projector file must override), each corner's local coordinates given by `project`.
std::string straight_local(const std::function<Eigen::Vector2d(const Geodetic&)>& project) {
  std::string body;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d xy = project(LocalFrame(kOrigin).to_geodetic(kCorners[size_t(i)]));
    body += "  <node id=\"" + std::to_string(i + 1) + "\" lat=\"0\" lon=\"0\">\n" +
            tags_xml({{"local_x", fixed(xy.x(), 5)}, {"local_y", fixed(xy.y(), 5)}, {"ele", "3.25"}}) + "  </node>\n";
  }
  return osm(body + way(10, {1, 2}) + way(11, {3, 4}) +
             relation(100, {{"way", 10, "left"}, {"way", 11, "right"}}, kRoad));
}

void expect_corners(const Lanelet2Map& map, double tolerance) {
  ASSERT_EQ(map.lanelets.size(), 1u);
  const auto& ll = map.lanelets[0];
  EXPECT_NEAR(ll.left_points[0].x(), -1.75, tolerance);
  EXPECT_NEAR(ll.left_points[0].y(), 0, tolerance);
  EXPECT_NEAR(ll.left_points[1].x(), -1.75, tolerance);
  EXPECT_NEAR(ll.left_points[1].y(), 50, tolerance);
  EXPECT_NEAR(ll.right_points[0].x(), 1.75, tolerance);
  EXPECT_NEAR(ll.right_points[0].y(), 0, tolerance);
  EXPECT_NEAR(ll.right_points[1].x(), 1.75, tolerance);
  EXPECT_NEAR(ll.right_points[1].y(), 50, tolerance);
}

// ---- Good maps ----

TEST(Lanelet2File, StraightLaneletIsThreeAndAHalfMetresWideAndPointsNorth) {
  const Lanelet2Map map = parse_lanelet2(straight(), "straight.osm", at_origin());
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::wgs84);
  ASSERT_EQ(map.lanelets.size(), 1u);
  const Lanelet2Lanelet& ll = map.lanelets[0];
  EXPECT_EQ(ll.id, 100);
  EXPECT_EQ(ll.subtype, "road");
  EXPECT_EQ(ll.location, "urban");
  EXPECT_EQ(ll.left, 10);
  EXPECT_EQ(ll.right, 11);
  EXPECT_FALSE(ll.left_inverted || ll.right_inverted);
  EXPECT_TRUE(ll.one_way);
  EXPECT_FALSE(ll.speed_limit_mps);
  EXPECT_EQ(ll.where, "straight.osm:19");
  ASSERT_EQ(ll.left_points.size(), 2u);
  ASSERT_EQ(ll.right_points.size(), 2u);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR((ll.right_points[i] - ll.left_points[i]).norm(), 3.5, 1e-3);
  const Eigen::Vector3d along = ll.left_points[1] - ll.left_points[0];
  EXPECT_NEAR(along.y(), 50, 1e-3);  // north
  EXPECT_NEAR(along.x(), 0, 1e-3);
  expect_corners(map, 1e-3);
  EXPECT_EQ(map.country, "de");  // the region tag, lower case
  ASSERT_NE(map.line(11), nullptr);
  EXPECT_EQ(map.line(11)->type, "curbstone");
  EXPECT_EQ(map.line(11)->subtype, "high");
  EXPECT_EQ(map.line(11)->point_ids, (std::vector<Lanelet2Id>{3, 4}));
  EXPECT_EQ(map.line(12), nullptr);
  EXPECT_TRUE(map.warnings.empty());
}

TEST(Lanelet2File, OriginIsTheCentreOfTheNodesBoundingBoxWhenNoneIsGiven) {
  // The lanelet spans x -1.75 .. 1.75, y 0 .. 50 about kOrigin: its box's centre is 25 m north of it.
  const Lanelet2Map map = parse_lanelet2(straight(), "straight.osm");
  const Geodetic centre = LocalFrame(kOrigin).to_geodetic({0, 25});
  EXPECT_NEAR(map.origin.lat_deg, centre.lat_deg, 1e-9);
  EXPECT_NEAR(map.origin.lon_deg, centre.lon_deg, 1e-9);
  const auto& ll = map.lanelets.at(0);
  EXPECT_NEAR(ll.left_points[0].x(), -1.75, 1e-3);
  EXPECT_NEAR(ll.left_points[0].y(), -25, 1e-3);
  EXPECT_NEAR(ll.right_points[1].x(), 1.75, 1e-3);
  EXPECT_NEAR(ll.right_points[1].y(), 25, 1e-3);
}

TEST(Lanelet2File, TagsOfTheLaneletAreRead) {
  std::string xml = straight();
  xml.replace(xml.find("<tag k=\"location\""), 0,
              "<tag k=\"one_way\" v=\"no\"/><tag k=\"speed_limit\" v=\"50 km/h\"/>");
  const Lanelet2Map map = parse_lanelet2(xml, "tags.osm");
  const auto& ll = map.lanelets.at(0);
  EXPECT_FALSE(ll.one_way);
  ASSERT_TRUE(ll.speed_limit_mps);
  EXPECT_NEAR(*ll.speed_limit_mps, 50 / 3.6, 1e-9);
}

TEST(Lanelet2File, InvertedSharedBoundIsReversed) {
  // tests/data/lanelet2/two_lanes.osm: lanes 2001 (north) and 2002 (south) share the middle line 1002,
  // drawn northwards; the west curb 1001 is drawn southwards.
  const Lanelet2Map map = read_lanelet2(kData + "two_lanes.osm", at_origin());
  ASSERT_EQ(map.lanelets.size(), 2u);
  const Lanelet2Lanelet& north = map.lanelets[0];
  const Lanelet2Lanelet& south = map.lanelets[1];
  EXPECT_FALSE(north.left_inverted || north.right_inverted);
  EXPECT_TRUE(south.left_inverted);
  EXPECT_FALSE(south.right_inverted);
  // Both bounds of the southbound lane run south, its right bound (x = -3.5) on its right.
  EXPECT_NEAR(south.left_points.front().y(), 40, 0.02);
  EXPECT_NEAR(south.left_points.back().y(), 0, 0.02);
  EXPECT_NEAR(south.right_points.front().y(), 40, 0.02);
  EXPECT_NEAR(south.right_points.front().x(), -3.5, 0.02);
  EXPECT_NEAR(south.left_points.front().x(), 0, 0.02);
  // The way itself keeps its order.
  EXPECT_LT(map.line(1002)->points.front().y(), map.line(1002)->points.back().y());
  ASSERT_TRUE(north.speed_limit_mps && south.speed_limit_mps);
  EXPECT_NEAR(*north.speed_limit_mps, 30 / 3.6, 1e-9);
  EXPECT_NEAR(*south.speed_limit_mps, 20 * 0.44704, 1e-9);
  EXPECT_EQ(north.regulatory_elements, (std::vector<Lanelet2Id>{3001}));
  EXPECT_EQ(map.country, "de");
}

TEST(Lanelet2File, LaneletWhoseBoundsAreBothDrawnBackwardsRunsAgainstThem) {
  // Lanelet2's align: both ways run north, but the "right" one lies west of the "left" one, so the
  // lanelet runs south with both bounds reversed.
  std::string xml = straight();
  xml.replace(xml.find("ref=\"10\" role=\"left\""), 20, "ref=\"11\" role=\"left\"");
  xml.replace(xml.find("ref=\"11\" role=\"right\""), 21, "ref=\"10\" role=\"right\"");
  const Lanelet2Map map = parse_lanelet2(xml, "swapped.osm", at_origin());
  const auto& ll = map.lanelets.at(0);
  EXPECT_TRUE(ll.left_inverted && ll.right_inverted);
  EXPECT_NEAR(ll.left_points.front().y(), 50, 1e-3);
  EXPECT_NEAR(ll.left_points.front().x(), 1.75, 1e-3);
}

TEST(Lanelet2File, AreasRegulatoryElementsAndOtherRelations) {
  const Lanelet2Map map = read_lanelet2(kData + "two_lanes.osm", at_origin());
  ASSERT_EQ(map.areas.size(), 1u);
  const Lanelet2Area& walkway = map.areas[0];
  EXPECT_EQ(walkway.subtype, "walkway");
  EXPECT_EQ(walkway.outer_ways, (std::vector<Lanelet2Id>{1006, 1007}));
  ASSERT_EQ(walkway.outer.size(), 1u);
  // Ways 54-51-52 and 54-53-52 joined end to end (the second reversed): one ring of four corners.
  ASSERT_EQ(walkway.outer[0].size(), 4u);
  EXPECT_NEAR(walkway.outer[0][0].x(), 3.6, 0.02);
  EXPECT_NEAR(walkway.outer[0][1].x(), 5.5, 0.02);
  EXPECT_NEAR(walkway.outer[0][2].y(), 40, 0.02);
  EXPECT_NEAR(walkway.outer[0][3].x(), 3.6, 0.02);
  EXPECT_NEAR(walkway.outer[0][3].y(), 40, 0.02);
  EXPECT_TRUE(walkway.inner.empty());

  ASSERT_EQ(map.regulatory.size(), 1u);
  EXPECT_EQ(map.regulatory[0].subtype, "traffic_sign");
  EXPECT_EQ(map.regulatory[0].members.at("refers"), (std::vector<Lanelet2Id>{1005}));
  EXPECT_EQ(map.regulatory[0].members.at("ref_line"), (std::vector<Lanelet2Id>{1004}));
  EXPECT_EQ(map.other_relations, (std::map<std::string, int>{{"route", 1}}));
  EXPECT_EQ(map.lines.size(), 7u);
}

TEST(Lanelet2File, JoinsAnAreaOfOneClosedWayAndHoles) {
  const std::string extra =
      node_at(61, 10, 0) + node_at(62, 20, 0) + node_at(63, 20, 10) + node_at(64, 10, 10) + node_at(65, 12, 2) +
      node_at(66, 14, 2) + node_at(67, 14, 4) + way(70, {61, 62, 63, 64, 61}) + way(71, {65, 66}) + way(72, {67, 66}) +
      way(73, {67, 65}) +
      relation(200, {{"way", 70, "outer"}, {"way", 71, "inner"}, {"way", 72, "inner"}, {"way", 73, "inner"}},
               {{"type", "multipolygon"}, {"subtype", "parking"}});
  const Lanelet2Map map = parse_lanelet2(straight(3.5, extra), "area.osm", at_origin());
  ASSERT_EQ(map.areas.size(), 1u);
  EXPECT_EQ(map.areas[0].outer.at(0).size(), 4u);
  ASSERT_EQ(map.areas[0].inner.size(), 1u);
  EXPECT_EQ(map.areas[0].inner[0].size(), 3u);
}

// A node's local_x / local_y as Autoware's TransverseMercator projector writes them: metres on the
// transverse Mercator of scale factor k0 about the origin's meridian, from the origin.
Eigen::Vector2d autoware_tm(const Geodetic& g, double k0) {
  const GeographicLib::TransverseMercator tm(GeographicLib::Constants::WGS84_a(), GeographicLib::Constants::WGS84_f(),
                                             k0);
  double x0 = 0, y0 = 0, x = 0, y = 0;
  tm.Forward(kOrigin.lon_deg, kOrigin.lat_deg, kOrigin.lon_deg, x0, y0);
  tm.Forward(kOrigin.lon_deg, g.lat_deg, g.lon_deg, x, y);
  return {x - x0, y - y0};
}

TEST(Lanelet2File, TransverseMercatorLocalCoordinatesGiveTheSamePointsAsLatLon) {
  const TempDir dir;
  const std::string path =
      dir.write("lanelet2_map.osm", straight_local([](const Geodetic& g) { return autoware_tm(g, 0.9996); }));
  dir.write("map_projector_info.yaml",
            "projector_type: TransverseMercator\nvertical_datum: WGS84\n"
            "map_origin:\n  latitude: 49.0\n  longitude: 8.4\n  altitude: 110.0\n");
  const Lanelet2Map local = read_lanelet2(path);  // origin: the projector's map_origin
  EXPECT_EQ(local.coordinates, Lanelet2Coordinates::transverse_mercator);
  EXPECT_DOUBLE_EQ(local.origin.lat_deg, 49.0);
  EXPECT_DOUBLE_EQ(local.origin.alt_m, 110.0);
  expect_corners(local, 0.01);
  const Lanelet2Map wgs84 = parse_lanelet2(straight(), "straight.osm", at_origin());
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_LT((local.lanelets[0].left_points[i] - wgs84.lanelets[0].left_points[i]).head<2>().norm(), 0.01);
    EXPECT_LT((local.lanelets[0].right_points[i] - wgs84.lanelets[0].right_points[i]).head<2>().norm(), 0.01);
  }
  EXPECT_DOUBLE_EQ(local.lanelets[0].left_points[0].z(), 3.25);  // ele
}

TEST(Lanelet2File, TransverseMercatorScaleFactorIsRead) {
  const TempDir dir;
  const std::string path =
      dir.write("lanelet2_map.osm", straight_local([](const Geodetic& g) { return autoware_tm(g, 1.0); }));
  dir.write("map_projector_info.yaml",
            "projector_type: TransverseMercator\nvertical_datum: WGS84\nscale_factor: 1.0\n"
            "map_origin: {latitude: 49.0, longitude: 8.4}\n");
  expect_corners(read_lanelet2(path, at_origin()), 0.01);
}

TEST(Lanelet2File, LocalCartesianUtmCoordinatesAreRelativeToTheOriginsUtmPosition) {
  const Geodetic utm_origin{49.001, 8.402, 0};  // not the world's origin: the points must still land right
  const auto utm = [](const Geodetic& g) {
    int zone = 0;
    bool northp = false;
    double x = 0, y = 0;
    GeographicLib::UTMUPS::Forward(g.lat_deg, g.lon_deg, zone, northp, x, y);
    return Eigen::Vector2d(x, y);
  };
  const TempDir dir;
  const std::string path = dir.write(
      "lanelet2_map.osm", straight_local([&](const Geodetic& g) { return Eigen::Vector2d(utm(g) - utm(utm_origin)); }));
  dir.write("map_projector_info.yaml",
            "projector_type: LocalCartesianUTM\nvertical_datum: WGS84\n"
            "map_origin: {latitude: 49.001, longitude: 8.402, altitude: 0}\n");
  const Lanelet2Map map = read_lanelet2(path, at_origin());
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::local_cartesian_utm);
  expect_corners(map, 0.01);
}

TEST(Lanelet2File, MgrsCoordinatesAreMetresWithinTheGridSquare) {
  // Autoware's MGRS maps: local_x / local_y are the easting and northing within the 100 km square.
  int zone = 0;
  bool northp = false;
  double x = 0, y = 0;
  GeographicLib::UTMUPS::Forward(kOrigin.lat_deg, kOrigin.lon_deg, zone, northp, x, y);
  std::string grid;
  GeographicLib::MGRS::Forward(zone, northp, x, y, 0, grid);
  EXPECT_EQ(grid, "32UMV");  // 49.0 N, 8.4 E
  const auto in_square = [](const Geodetic& g) {
    int z = 0;
    bool n = false;
    double e = 0, north = 0;
    GeographicLib::UTMUPS::Forward(g.lat_deg, g.lon_deg, z, n, e, north);
    return Eigen::Vector2d(std::fmod(e, 100'000), std::fmod(north, 100'000));
  };
  const TempDir dir;
  const std::string path = dir.write("lanelet2_map.osm", straight_local(in_square));
  dir.write("map_projector_info.yaml", "projector_type: MGRS\nvertical_datum: WGS84\nmgrs_grid: " + grid + "\n");
  const Lanelet2Map map = read_lanelet2(path, at_origin());
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::mgrs);
  expect_corners(map, 0.01);
  // Without an origin: the grid square's south-west corner.
  const Lanelet2Map about_corner = read_lanelet2(path);
  double corner_lat = 0, corner_lon = 0;
  GeographicLib::UTMUPS::Reverse(zone, northp, std::floor(x / 1e5) * 1e5, std::floor(y / 1e5) * 1e5, corner_lat,
                                 corner_lon);
  EXPECT_NEAR(about_corner.origin.lat_deg, corner_lat, 1e-9);
  EXPECT_NEAR(about_corner.origin.lon_deg, corner_lon, 1e-9);
}

TEST(Lanelet2File, LocalProjectorTakesLocalCoordinatesAsTheWorldsMetres) {
  const TempDir dir;
  std::ifstream in(kData + "local_xy.osm");
  const std::string path = dir.write("lanelet2_map.osm", std::string(std::istreambuf_iterator<char>(in), {}));
  dir.write("map_projector_info.yaml", "projector_type: local\n");  // as Autoware's README writes it
  const Lanelet2Map map = read_lanelet2(path);
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::local);
  const auto& ll = map.lanelets.at(0);
  EXPECT_DOUBLE_EQ(ll.left_points[0].x(), 100.0);
  EXPECT_DOUBLE_EQ(ll.left_points[1].y(), 230.0);
  EXPECT_DOUBLE_EQ(ll.left_points[1].z(), 12.8);
  EXPECT_DOUBLE_EQ(ll.right_points[0].x(), 103.5);
  ASSERT_EQ(map.warnings.size(), 1u);  // no origin: placed at 0, 0
  EXPECT_NE(map.warnings[0].find("Local"), std::string::npos);
  EXPECT_TRUE(read_lanelet2(path, at_origin()).warnings.empty());
}

TEST(Lanelet2File, LocalCoordinatesWithoutAProjectorFileAreLocal) {
  const Lanelet2Map map = read_lanelet2(kData + "local_xy.osm");
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::local);
  EXPECT_DOUBLE_EQ(map.lanelets.at(0).right_points[1].y(), 230.0);
}

// ---- Bad input: one line naming the file, the line and the element ----

TEST(Lanelet2File, MalformedXmlNamesTheLine) {
  expect_parse_error("<?xml version=\"1.0\"?>\n<osm>\n  <node id=\"1\" lat=\"49\" lon=\"8\">\n</osm>\n",
                     {"bad.osm:4:", "malformed XML"});
  expect_parse_error("", {"bad.osm:1: malformed XML"});
  expect_parse_error("<?xml version=\"1.0\"?>\n<gpx/>\n", {"bad.osm", "no <osm>"});
}

TEST(Lanelet2File, WayNamingAMissingNode) {
  expect_parse_error(straight(3.5, way(12, {1, 77})), {"bad.osm:27:", "way 12", "node 77", "not a node of the file"});
}

TEST(Lanelet2File, RelationMemberNamingAMissingElement) {
  std::string xml = straight();
  xml.replace(xml.find("ref=\"10\" role=\"left\""), 8, "ref=\"88\"");
  expect_parse_error(xml, {"bad.osm:19:", "lanelet 100", "its left bound 88 is not a way of the file"});
  expect_parse_error(straight(3.5, relation(300, {{"node", 9, "refers"}}, {{"type", "regulatory_element"}})),
                     {"regulatory element 300", "node 9", "not a node of the file"});
  expect_parse_error(straight(3.5, relation(300, {{"relation", 555, "x"}}, {{"type", "route"}})),
                     {"relation 300", "relation 555", "not a relation of the file"});
  expect_parse_error(
      straight(3.5, relation(300, {{"way", 10, "left"}, {"way", 11, "right"}, {"relation", 9, "regulatory_element"}},
                             kRoad)),
      {"lanelet 300", "regulatory element 9", "not a relation of the file"});
}

TEST(Lanelet2File, LaneletWithoutLeftOrRight) {
  std::string xml = straight();
  const std::string left = "    <member type=\"way\" ref=\"10\" role=\"left\"/>\n";
  xml.erase(xml.find(left), left.size());
  expect_parse_error(xml, {"bad.osm:19:", "lanelet 100", "no left bound"});
  expect_parse_error(straight(3.5, relation(101, {{"way", 10, "left"}}, kRoad)), {"lanelet 101", "no right bound"});
  expect_parse_error(
      straight(3.5, relation(101, {{"way", 10, "left"}, {"way", 11, "right"}, {"way", 11, "right"}}, kRoad)),
      {"lanelet 101", "more than one", "right"});
  expect_parse_error(straight(3.5, relation(101, {{"node", 1, "left"}, {"way", 11, "right"}}, kRoad)),
                     {"lanelet 101", "left bound 1 is a node, not a way"});
}

TEST(Lanelet2File, LaneletWhoseBoundsCross) {
  // An X: the left bound runs from the west to the east side and the right bound the other way.
  const std::string x =
      osm(node_at(1, -1.75, 0) + node_at(2, 1.75, 50) + node_at(3, 1.75, 0) + node_at(4, -1.75, 50) + way(10, {1, 2}) +
          way(11, {3, 4}) + relation(100, {{"way", 10, "left"}, {"way", 11, "right"}}, kRoad));
  expect_error([&] { parse_lanelet2(x, "bad.osm", at_origin()); },
               {"bad.osm:15: lanelet 100: its left bound 10 and right bound 11 cross each other at (", "25.00)"});
  // A right bound drawn the other way that still crosses the left one with either direction.
  const std::string z = osm(node_at(1, -1.75, 0) + node_at(2, -1.75, 50) + node_at(3, 1.75, 50) + node_at(5, -3, 20) +
                            node_at(4, 1.75, 0) + way(10, {1, 2}) + way(11, {3, 5, 4}) +
                            relation(100, {{"way", 10, "left"}, {"way", 11, "right"}}, kRoad));
  expect_parse_error(z, {"lanelet 100", "cross each other", "reversed"});
}

TEST(Lanelet2File, MapWithoutLanelets) {
  expect_parse_error(osm(node_at(1, 0, 0) + node_at(2, 0, 5) + way(10, {1, 2})), {"bad.osm: no lanelets"});
}

TEST(Lanelet2File, NodeFarFromTheOriginIsNamed) {
  // A stray node at lat 0, lon 0 in a map of Karlsruhe.
  expect_parse_error(straight(3.5, "  <node id=\"999\" lat=\"0\" lon=\"0\"/>\n"),
                     {"bad.osm:27:", "node 999", "km from the map's origin"});
  Lanelet2ReadOptions near;
  near.origin = kOrigin;
  near.max_extent_m = 40;  // the lanelet reaches 50 m north
  expect_error([&] { parse_lanelet2(straight(), "bad.osm", near); },
               {"bad.osm:", "node 2", "km from the map's origin"});
}

TEST(Lanelet2File, LineStringOfOnePoint) {
  expect_parse_error(straight(3.5, way(12, {1}, {{"type", "curbstone"}})), {"bad.osm:27:", "way 12", "1 point"});
  expect_parse_error(straight(3.5, way(12, {})), {"way 12", "0 points"});
}

TEST(Lanelet2File, NonNumericCoordinates) {
  std::string xml = straight();
  xml.replace(xml.find("lat=\"") + 5, 2, "4x");
  expect_parse_error(xml, {"bad.osm:3:", "node 1", "lat '4x", "not a number"});
  expect_parse_error(osm("<node id=\"5\"><tag k=\"local_x\" v=\"1e\"/><tag k=\"local_y\" v=\"2\"/></node>"),
                     {"node 5", "local_x '1e' is not a number"});
  expect_parse_error(osm("<node id=\"5\" lat=\"49\" lon=\"8\"><tag k=\"ele\" v=\"high\"/></node>"),
                     {"node 5", "ele 'high' is not a number"});
  expect_parse_error(osm("<node id=\"5\" lat=\"nan\" lon=\"8\"/>"), {"node 5", "lat 'nan' is not a number"});
  expect_parse_error(osm("<node id=\"5\" lat=\"91\" lon=\"8\"/>"), {"node 5", "not a place on Earth"});
  expect_parse_error(osm("<node id=\"x5\" lat=\"49\" lon=\"8\"/>"), {"bad.osm:3:", "without a valid id", "'x5'"});
}

TEST(Lanelet2File, NodeWithoutCoordinates) {
  expect_parse_error(straight(3.5, "  <node id=\"7\"/>\n"),
                     {"bad.osm:27:", "node 7", "neither lat / lon nor local_x / local_y"});
  expect_parse_error(straight(3.5, "  <node id=\"7\" lat=\"49\"/>\n"), {"node 7", "not both"});
  // Without a projector file a node with local coordinates only cannot join lat / lon nodes.
  expect_parse_error(
      straight(3.5, "  <node id=\"7\"><tag k=\"local_x\" v=\"1\"/><tag k=\"local_y\" v=\"2\"/></node>\n"),
      {"node 7", "no lat / lon"});
}

TEST(Lanelet2File, AreaRingThatDoesNotClose) {
  const std::string extra = node_at(61, 10, 0) + node_at(62, 20, 0) + node_at(63, 20, 10) + way(70, {61, 62}) +
                            way(71, {62, 63}) +
                            relation(200, {{"way", 70, "outer"}, {"way", 71, "outer"}}, {{"type", "multipolygon"}});
  expect_parse_error(straight(3.5, extra), {"multipolygon 200", "outer ring does not close", "way 71", "node 63"});
}

TEST(Lanelet2File, DuplicateIds) {
  expect_parse_error(straight(3.5, node_at(1, 5, 5)), {"bad.osm:27:", "node 1", "second node", "bad.osm:3"});
}

TEST(Lanelet2File, BadProjectorFile) {
  const TempDir dir;
  const std::string path = dir.write("lanelet2_map.osm", straight());
  dir.write("map_projector_info.yaml", "projector_type: LambertConformal\n");
  expect_error([&] { read_lanelet2(path); }, {"map_projector_info.yaml:1", "LambertConformal"});
  dir.write("map_projector_info.yaml", "projector_type: MGRS\nmgrs_grid: 99ZZZ\n");
  expect_error([&] { read_lanelet2(path); }, {"map_projector_info.yaml:2", "99ZZZ", "not an MGRS grid square"});
  dir.write("map_projector_info.yaml", "projector_type: TransverseMercator\n");
  expect_error([&] { read_lanelet2(path); }, {"map_projector_info.yaml", "map_origin"});
  expect_error([&] { read_lanelet2(path + ".missing"); }, {"lanelet2_map.osm.missing", "cannot open"});
}

// ---- The real Karlsruhe example map (Lanelet2's, BSD-3; in ../shared, never in this repository) ----

TEST(Lanelet2File, KarlsruheExampleMap) {
  const std::string path =
      std::string(LIDARLOOP_DATA_DIR) + "/../shared/data/maps/lanelet2/karlsruhe_mapping_example.osm";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not there";
  const Lanelet2Map map = read_lanelet2(path);
  EXPECT_EQ(map.coordinates, Lanelet2Coordinates::wgs84);
  const auto lanelets = [&](const std::string& subtype) {
    return std::count_if(map.lanelets.begin(), map.lanelets.end(),
                         [&](const auto& ll) { return ll.subtype == subtype; });
  };
  const auto lines = [&](const std::string& type) {
    return std::count_if(map.lines.begin(), map.lines.end(), [&](const auto& l) { return l.second.type == type; });
  };
  EXPECT_EQ(lanelets("road"), 337);
  EXPECT_EQ(lanelets("crosswalk"), 8);
  EXPECT_EQ(lines("curbstone"), 325);
  EXPECT_EQ(lines("road_border"), 238);
  EXPECT_EQ(map.country, "de");
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e9), hi = -lo;
  for (const auto& [id, line] : map.lines)
    for (const auto& p : line.points) lo = lo.cwiseMin(p.head<2>()), hi = hi.cwiseMax(p.head<2>());
  const Eigen::Vector2d span = hi - lo;
  EXPECT_NEAR(std::min(span.x(), span.y()), 1000, 150) << span.transpose();
  EXPECT_NEAR(std::max(span.x(), span.y()), 3400, 200) << span.transpose();
  EXPECT_FALSE(map.areas.empty());
  EXPECT_FALSE(map.regulatory.empty());
}

}  // namespace
}  // namespace lidarloop
