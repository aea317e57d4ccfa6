// Reading OpenDRIVE maps (sim/opendrive_file.hpp) and evaluating them (sim/opendrive_geometry.hpp):
// reference lines and lanes against analytic truth, each bad input's one-line message, and the real
// maps (CARLA's Town01, esmini's fabriksgatan) from ../shared when they are there.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "sim/opendrive_file.hpp"
#include "sim/opendrive_geometry.hpp"
#include "tests/sim/opendrive_test_maps.hpp"

namespace lidarloop {
namespace {

using namespace odr_test;

const std::string kShared = std::string(LIDARLOOP_DATA_DIR) + "/../shared/data/maps/opendrive/";
const std::string kOneLane = section("", lane(-1, "driving", 3.5));

// Fresnel integrals C(x) = int_0^x cos(pi t^2 / 2) dt and S(x) by their power series (Abramowitz &
// Stegun 7.3.11-12), independent of the quadrature under test; converges fast for x below 3.
Eigen::Vector2d fresnel(double x) {
  double c = 0, s = 0, term = x;  // term = (-1)^n (pi/2)^(2n) x^(4n+1) / (2n)!
  const double a = M_PI / 2;
  for (int n = 0; n < 40; ++n) {
    c += term / (4 * n + 1);
    const double next = term * a * x * x / (2 * n + 1);  // (pi/2)^(2n+1) x^(4n+3) / (2n+1)!
    s += next / (4 * n + 3);
    term = -next * a * x * x / (2 * n + 2);
  }
  return {c, s};
}

OdrMap one_road(const std::string& shape, double length, double x = 0, double y = 0, double hdg = 0,
                const std::string& lanes = kOneLane, const std::string& extra = "") {
  return parse_opendrive(map_text(road("7", length, shape, lanes, extra, x, y, hdg)), "test.xodr");
}

TEST(OpenDriveGeometry, ClothoidFromStraightEndsWhereTheFresnelIntegralsPutIt) {
  for (const double radius : {30.0, 100.0, 500.0}) {
    const double length = 60;  // curvature 0 -> 1/R over L
    const OdrMap map = one_road("<spiral curvStart=\"0\" curvEnd=\"" + num(1 / radius) + "\"/>", length);
    const OdrPose end = reference_pose(map.roads[0], length);
    const double a = std::sqrt(M_PI * radius * length);  // heading pi tau^2 / 2 with u = a tau
    const Eigen::Vector2d f = fresnel(length / a) * a;
    EXPECT_NEAR(end.x, f.x(), 1e-3) << "R " << radius;
    EXPECT_NEAR(end.y, f.y(), 1e-3) << "R " << radius;
    EXPECT_NEAR(end.x, f.x(), 1e-8) << "the quadrature is far better than the millimetre asked";
    EXPECT_NEAR(end.y, f.y(), 1e-8);
    EXPECT_NEAR(end.hdg, length / (2 * radius), 1e-12);
  }
}

TEST(OpenDriveGeometry, ClothoidOfConstantCurvatureIsAnArc) {
  const double k = -1.0 / 40;
  const OdrMap spiral = one_road("<spiral curvStart=\"" + num(k) + "\" curvEnd=\"" + num(k) + "\"/>", 50, 3, 4, 0.3);
  const OdrMap arc = one_road("<arc curvature=\"" + num(k) + "\"/>", 50, 3, 4, 0.3);
  for (const double s : {0.0, 17.0, 50.0}) {
    const OdrPose p = reference_pose(spiral.roads[0], s), q = reference_pose(arc.roads[0], s);
    EXPECT_NEAR(p.x, q.x, 1e-9);
    EXPECT_NEAR(p.y, q.y, 1e-9);
    EXPECT_NEAR(p.hdg, q.hdg, 1e-12);
  }
}

TEST(OpenDriveGeometry, ArcEndPointAndHeading) {
  for (const double radius : {25.0, -60.0}) {
    const double x0 = 10, y0 = -5, h0 = 0.7, length = 35;
    const OdrMap map = one_road("<arc curvature=\"" + num(1 / radius) + "\"/>", length, x0, y0, h0);
    const OdrPose end = reference_pose(map.roads[0], length);
    const double h1 = h0 + length / radius;
    EXPECT_NEAR(end.x, x0 + radius * (std::sin(h1) - std::sin(h0)), 1e-9);
    EXPECT_NEAR(end.y, y0 - radius * (std::cos(h1) - std::cos(h0)), 1e-9);
    EXPECT_NEAR(end.hdg, h1, 1e-12);
  }
}

TEST(OpenDriveGeometry, ParamPoly3InBothParameterisations) {
  // u = p, v = c p^2 over p in [0, L] (arcLength) is u = L q, v = c L^2 q^2 over q in [0, 1] (normalized).
  const double length = 20, c = 0.01, hdg = 0.4, x0 = 1, y0 = 2;
  const OdrMap by_length = one_road(
      "<paramPoly3 pRange=\"arcLength\" aU=\"0\" bU=\"1\" cU=\"0\" dU=\"0\" aV=\"0\" "
      "bV=\"0\" cV=\"" +
          num(c) + "\" dV=\"0\"/>",
      length, x0, y0, hdg);
  const OdrMap normalized =
      one_road("<paramPoly3 pRange=\"normalized\" aU=\"0\" bU=\"" + num(length) +
                   "\" cU=\"0\" dU=\"0\" aV=\"0\" bV=\"0\" cV=\"" + num(c * length * length) + "\" dV=\"0\"/>",
               length, x0, y0, hdg);
  for (const double s : {0.0, 5.0, 20.0}) {
    const double u = s, v = c * s * s;
    const double x = x0 + std::cos(hdg) * u - std::sin(hdg) * v, y = y0 + std::sin(hdg) * u + std::cos(hdg) * v;
    const double h = hdg + std::atan(2 * c * s);
    for (const OdrMap* m : {&by_length, &normalized}) {
      const OdrPose p = reference_pose(m->roads[0], s);
      EXPECT_NEAR(p.x, x, 1e-9) << "s " << s;
      EXPECT_NEAR(p.y, y, 1e-9) << "s " << s;
      EXPECT_NEAR(p.hdg, h, 1e-12) << "s " << s;
    }
  }
}

TEST(OpenDriveGeometry, Poly3IsFollowedByArcLength) {
  // v = 0.5 u: a straight line at atan(0.5), so arc length s is at u = s / sqrt(1.25).
  const OdrMap map = one_road("<poly3 a=\"0\" b=\"0.5\" c=\"0\" d=\"0\"/>", 30);
  const OdrPose p = reference_pose(map.roads[0], 30);
  EXPECT_NEAR(p.x, 30 / std::sqrt(1.25), 1e-9);
  EXPECT_NEAR(p.y, 15 / std::sqrt(1.25), 1e-9);
  EXPECT_NEAR(p.hdg, std::atan(0.5), 1e-12);
}

TEST(OpenDriveGeometry, LaneWidthAndHeightAtS) {
  // Section from s = 20; lane -1: width 3 + 0.02 ds - 0.001 ds^2 for ds < 10, then 3.5 + 0.01 (ds - 10).
  // Lane -2 (a sidewalk): 2 m wide, 0.12 m high at its inner edge and 0.15 m at its outer.
  const std::string right =
      "          <lane id=\"-1\" type=\"driving\"><width sOffset=\"0\" a=\"3\" b=\"0.02\" c=\"-0.001\" d=\"0\"/>"
      "<width sOffset=\"10\" a=\"3.5\" b=\"0.01\" c=\"0\" d=\"0\"/></lane>\n"
      "          <lane id=\"-2\" type=\"sidewalk\"><width sOffset=\"0\" a=\"2\"/>"
      "<height sOffset=\"0\" inner=\"0.12\" outer=\"0.15\"/></lane>\n";
  const std::string lanes = section("", lane(-1, "driving", 3)) + section("", right, 20);
  const std::string extra =
      "    <elevationProfile><elevation s=\"0\" a=\"1\" b=\"0.05\" c=\"0\" d=\"0\"/></elevationProfile>\n";
  const OdrMap map = parse_opendrive(
      map_text(road("7", 60, "<line/>", "      <laneOffset s=\"0\" a=\"0.5\"/>\n" + lanes, extra)), "t");
  const OdrRoad& r = map.roads[0];
  ASSERT_EQ(r.sections.size(), 2u);
  EXPECT_EQ(r.section_at(25), 1u);
  EXPECT_NEAR(lane_width(r, 1, -1, 25), 3 + 0.02 * 5 - 0.001 * 25, 1e-12);
  EXPECT_NEAR(lane_width(r, 1, -1, 40), 3.5 + 0.01 * 10, 1e-12);
  const OdrLaneEdges e = lane_edges(r, 1, -2, 40);
  EXPECT_NEAR(e.inner, 0.5 - 3.6, 1e-12);  // the lane offset, then lane -1
  EXPECT_NEAR(e.outer, 0.5 - 5.6, 1e-12);
  const OdrLane& sidewalk = *r.sections[1].lane(-2);
  EXPECT_NEAR(lane_height(sidewalk, 20, 0.5), 0.135, 1e-12);
  const Eigen::Vector3d p = lane_surface_point(r, 1, sidewalk, 40, 0.5 * (e.inner + e.outer));
  EXPECT_NEAR(p.z(), 1 + 0.05 * 40 + 0.135, 1e-12);
  EXPECT_NEAR(p.y(), 0.5 * (e.inner + e.outer), 1e-12);
}

TEST(OpenDriveGeometry, SuperelevationLowersTheRightSideAndLevelLanesStayLevel) {
  const std::string extra =
      "    <lateralProfile><superelevation s=\"0\" a=\"0.04\" b=\"0\" c=\"0\" d=\"0\"/></lateralProfile>\n";
  const std::string right = lane(-1, "driving", 3.5) +
                            "          <lane id=\"-2\" type=\"sidewalk\" level=\"true\"><width sOffset=\"0\" "
                            "a=\"2\"/></lane>\n";
  const OdrMap map = one_road("<line/>", 30, 0, 0, 0, section("", right), extra);
  const OdrRoad& r = map.roads[0];
  EXPECT_NEAR(road_point(r, 10, -3.5).z(), -3.5 * std::tan(0.04), 1e-12);
  EXPECT_NEAR(road_point(r, 10, 2).z(), 2 * std::tan(0.04), 1e-12);
  const OdrLane& level = *r.sections[0].lane(-2);
  EXPECT_NEAR(lane_surface_point(r, 0, level, 10, -5).z(), -3.5 * std::tan(0.04), 1e-12);
}

TEST(OpenDriveGeometry, BorderGivesTheOuterEdge) {
  const std::string right =
      "          <lane id=\"-1\" type=\"driving\"><border sOffset=\"0\" a=\"3\" b=\"0.1\"/></lane>\n" +
      lane(-2, "sidewalk", 2);
  const OdrMap map = one_road("<line/>", 10, 0, 0, 0, section("", right));
  EXPECT_NEAR(lane_edges(map.roads[0], 0, -1, 5).outer, -3.5, 1e-12);
  EXPECT_NEAR(lane_edges(map.roads[0], 0, -2, 5).outer, -5.5, 1e-12);
}

TEST(OpenDriveFile, ReadsMarksObjectsJunctionsAndTheOrigin) {
  const std::string mark =
      "            <roadMark sOffset=\"0\" type=\"solid solid\" weight=\"bold\" color=\"yellow\" width=\"0.2\">"
      "<type name=\"x\"><line length=\"2\" space=\"4\" tOffset=\"0.1\" sOffset=\"1\" "
      "width=\"0.15\"/></type></roadMark>\n";
  const std::string objects =
      "    <objects><object id=\"9\" type=\"crosswalk\" s=\"5\" t=\"0\" hdg=\"0\" length=\"4\" width=\"7\">"
      "<outline><cornerRoad s=\"3\" t=\"-3.5\"/><cornerRoad s=\"7\" t=\"-3.5\"/><cornerRoad s=\"7\" t=\"3.5\"/>"
      "<cornerRoad s=\"3\" t=\"3.5\"/></outline></object>"
      "<object id=\"10\" type=\"pole\" s=\"8\" t=\"-6\" radius=\"0.1\" height=\"4\"/></objects>\n";
  const std::string body =
      road("1", 20, "<line/>", section("", lane(-1, "driving", 3.5, mark)),
           "    <link><successor elementType=\"junction\" "
           "elementId=\"100\"/></link>\n") +
      road("2", 10, "<line/>", section("", lane(-1, "driving", 3.5)), "", 20, 0, 0, "100") +
      road("3", 20, "<line/>", section("", lane(-1, "driving", 3.5)) + "", objects, 30, 0) +
      "  <junction id=\"100\" name=\"j\"><connection id=\"0\" incomingRoad=\"1\" connectingRoad=\"2\" "
      "contactPoint=\"start\"><laneLink from=\"-1\" to=\"-1\"/></connection></junction>\n";
  const OdrMap map = parse_opendrive(map_text(body), "t.xodr");
  ASSERT_EQ(map.roads.size(), 3u);
  EXPECT_TRUE(map.origin_from_map);
  EXPECT_DOUBLE_EQ(map.origin.lat_deg, 49);
  EXPECT_DOUBLE_EQ(map.origin.lon_deg, 8);
  const OdrRoadMark& m = map.roads[0].sections[0].right[0].marks.at(0);
  EXPECT_EQ(m.type, "solid solid");
  EXPECT_EQ(m.weight, "bold");
  EXPECT_EQ(m.color, "yellow");
  EXPECT_DOUBLE_EQ(*m.width, 0.2);
  ASSERT_EQ(m.lines.size(), 1u);
  EXPECT_DOUBLE_EQ(m.lines[0].length, 2);
  EXPECT_DOUBLE_EQ(m.lines[0].space, 4);
  EXPECT_DOUBLE_EQ(m.lines[0].t_offset, 0.1);
  EXPECT_DOUBLE_EQ(m.lines[0].width, 0.15);
  ASSERT_EQ(map.roads[2].objects.size(), 2u);
  EXPECT_EQ(map.roads[2].objects[0].type, "crosswalk");
  ASSERT_EQ(map.roads[2].objects[0].outlines.size(), 1u);
  EXPECT_EQ(map.roads[2].objects[0].outlines[0].size(), 4u);
  EXPECT_TRUE(map.roads[2].objects[0].outlines[0][0].road_frame);
  EXPECT_DOUBLE_EQ(map.roads[2].objects[1].radius, 0.1);
  ASSERT_EQ(map.junctions.size(), 1u);
  EXPECT_EQ(map.junctions[0].connections.at(0).connecting_road, "2");
  EXPECT_EQ(map.junctions[0].connections[0].lane_links.at(0).to, -1);
  EXPECT_EQ(map.road("2")->junction, "100");
}

TEST(OpenDriveFile, RepeatedObjectsAreOneCopyEveryDistanceAndAContinuousOneIsNamed) {
  // Street lights every 10 m from s = 2 over 30 m, moving out from t = -5 to -8 and growing from 4 to
  // 7 m: four copies, at s = 2, 12, 22, 32. A railing repeated continuously (distance 0) stays one.
  const std::string objects =
      "    <objects><object id=\"1\" type=\"pole\" s=\"2\" t=\"-5\" radius=\"0.1\" height=\"4\">"
      "<repeat s=\"2\" length=\"30\" distance=\"10\" tStart=\"-5\" tEnd=\"-8\" heightStart=\"4\" "
      "heightEnd=\"7\" zOffsetStart=\"0\" zOffsetEnd=\"0\"/></object>"
      "<object id=\"2\" type=\"railing\" s=\"0\" t=\"6\"><repeat s=\"0\" length=\"40\" distance=\"0\" "
      "tStart=\"6\" tEnd=\"6\"/></object></objects>\n";
  const OdrMap map = parse_opendrive(map_text(road("1", 40, "<line/>", kOneLane, objects)), "t.xodr");
  const auto& o = map.roads[0].objects;
  ASSERT_EQ(o.size(), 5u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(o[k].type, "pole");
    EXPECT_DOUBLE_EQ(o[k].s, 2 + 10 * k);
    EXPECT_DOUBLE_EQ(o[k].t, -5 - k);
    EXPECT_DOUBLE_EQ(o[k].height, 4 + k);
    EXPECT_DOUBLE_EQ(o[k].radius, 0.1);  // no radiusStart: the object's own
  }
  EXPECT_EQ(o[4].type, "continuous railing");
  // A distance that would make millions of copies is an error at its line, not a hang.
  const std::string flood =
      "    <objects><object id=\"3\" type=\"pole\" s=\"0\"><repeat s=\"0\" length=\"40\" "
      "distance=\"0.00001\"/></object></objects>\n";
  try {
    parse_opendrive(map_text(road("1", 40, "<line/>", kOneLane, flood)), "t.xodr");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.xodr:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("repeats more than 10000 times"), std::string::npos) << e.what();
  }
}

TEST(OpenDriveFile, PlaceholderGeoReferenceTakesTheWorldsOrigin) {
  OdrReadOptions options;
  options.origin = Geodetic{48.1, 11.5, 0};
  for (const std::string geo : {"", "+proj=tmerc +lat_0=0 +lon_0=0", "+proj=tmerc"}) {
    const OdrMap map = parse_opendrive(map_text(road("1", 10, "<line/>", kOneLane), geo), "t.xodr", options);
    EXPECT_FALSE(map.origin_from_map) << geo;
    EXPECT_DOUBLE_EQ(map.origin.lat_deg, 48.1);
    ASSERT_EQ(map.warnings.size(), 1u) << geo;
    EXPECT_NE(map.warnings[0].find("world's origin"), std::string::npos) << map.warnings[0];
  }
}

TEST(OpenDriveFile, GeoReferenceAndHeaderOffsetPlaceTheMapsOrigin) {
  // The header's offset takes the map's (0, 0) to the projection's (offset.x, offset.y).
  auto with_offset = [](const std::string& geo, double x, double y) {
    std::string text = map_text(road("1", 10, "<line/>", kOneLane), geo);
    text.replace(text.find("  </header>"), 0,
                 "    <offset x=\"" + num(x) + "\" y=\"" + num(y) + "\" z=\"0\" hdg=\"0\"/>\n");
    return parse_opendrive(text, "t.xodr");
  };
  // 1 km east of lat 49, lon 8 on a transverse Mercator centred there: 1000 m / (N cos(lat)) of
  // longitude, N = a / sqrt(1 - e^2 sin^2(lat)) = 6,390,330 m, so 0.013667 deg, on the same parallel.
  const OdrMap east = with_offset("+proj=tmerc +lat_0=49 +lon_0=8 +k=1 +x_0=0 +y_0=0", 1000, 0);
  EXPECT_TRUE(east.origin_from_map);
  EXPECT_NEAR(east.origin.lat_deg, 49, 1e-6);
  EXPECT_NEAR(east.origin.lon_deg, 8.013667, 2e-6);
  // UTM zone 32 north: easting 500 km is its central meridian, 9 deg east, where the northing is 0.9996
  // of the meridian arc from the equator (Helmert's series on WGS84, solved here by bisection).
  const OdrMap utm = with_offset("+proj=utm +zone=32 +ellps=WGS84 +units=m +no_defs", 500000, 5427000);
  EXPECT_TRUE(utm.origin_from_map);
  EXPECT_NEAR(utm.origin.lon_deg, 9, 1e-9);
  const double a = 6378137, f = 1 / 298.257223563, e2 = f * (2 - f), e4 = e2 * e2, e6 = e4 * e2;
  auto arc = [&](double phi) {
    return a * ((1 - e2 / 4 - 3 * e4 / 64 - 5 * e6 / 256) * phi -
                (3 * e2 / 8 + 3 * e4 / 32 + 45 * e6 / 1024) * std::sin(2 * phi) +
                (15 * e4 / 256 + 45 * e6 / 1024) * std::sin(4 * phi) - (35 * e6 / 3072) * std::sin(6 * phi));
  };
  double lo = 0.8, hi = 0.9;
  for (int k = 0; k < 60; ++k) (0.9996 * arc((lo + hi) / 2) < 5427000 ? lo : hi) = (lo + hi) / 2;
  EXPECT_NEAR(utm.origin.lat_deg, lo * 180 / M_PI, 1e-7);
  ASSERT_EQ(utm.warnings.size(), 1u);
  EXPECT_NE(utm.warnings[0].find("UTM grid metres"), std::string::npos) << utm.warnings[0];
  // UTM without an offset puts the map at easting 0, outside any zone: a placeholder.
  EXPECT_FALSE(with_offset("+proj=utm +zone=32", 0, 0).origin_from_map);
}

// The message of the InputError that parsing `text` throws.
std::string error_of(const std::string& text) {
  try {
    parse_opendrive(text, "bad.xodr");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OpenDriveFile, BadInputIsOneLineNamingFileRoadAndS) {
  struct Case {
    std::string text, expect;
  };
  const std::string good_lanes = kOneLane;
  const Case cases[] = {
      {"<OpenDRIVE><header>", "bad.xodr:1: not XML"},
      {"<?xml version=\"1.0\"?>\n<osm version=\"0.6\"/>", "bad.xodr:2: not an OpenDRIVE file"},
      // The fuzzer's: a revision beyond an int's range was converted to int, undefined behaviour.
      {"<?xml version=\"1.0\"?>\n<OpenDRIVE><header revMajor=\"1\" revMinor=\"7e114\"/></OpenDRIVE>",
       "header revMinor is not a revision number: '7e114'"},
      {map_text(road("7", 10, "<clothoid/>", good_lanes)), "road 7 at s=0: unknown geometry 'clothoid'"},
      {map_text(road("7", 10, "<line/>", good_lanes,
                     "    <link><successor elementType=\"road\" elementId=\"42\" contactPoint=\"start\"/></link>\n")),
       "road 7 at s=10: successor road '42' is not in the map"},
      {map_text(road("7", 10, "<line/>",
                     section("",
                             "          <lane id=\"-1\" type=\"driving\"><width sOffset=\"0\" a=\"1\" "
                             "b=\"-0.2\"/></lane>\n"))),
       "road 7 at s=5: lane -1 width goes negative"},
      {map_text(road("7", 10,
                     "<paramPoly3 pRange=\"normalized\" aU=\"0\" bU=\"10\" cU=\"-15\" dU=\"0\" aV=\"0\" bV=\"0\" "
                     "cV=\"0\" dV=\"0\"/>",
                     good_lanes)),
       "paramPoly3 folds back"},
      {map_text(road("7", 10, "<line/>", "")), "road 7: no laneSection"},
      {map_text(road("7", 10, "<arc curvature=\"x\"/>", good_lanes)), "road 7: arc curvature is not a number: 'x'"},
      {map_text(road("7", 10, "<arc curvature=\"1e9\"/>", good_lanes)), "road 7 at s=0: arc curvature beyond 100 1/m"},
      {map_text(road("7", 10, "<line/>", section("", lane(-1, "driving", 1e9)))),
       "road 7 at s=0: lane width beyond 1000 m"},
      {map_text(road("7", 10, "<line/>", good_lanes) +
                "  <junction id=\"1\"><connection id=\"0\" incomingRoad=\"7\" connectingRoad=\"8\"/></junction>\n"),
       "road '8' is not in the map"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.expect), std::string::npos) << e << "\n  expected: " << c.expect;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(e.rfind("bad.xodr:", 0), 0u) << e;
  }
}

TEST(OpenDriveFile, NegativeWidthNamesWhereItGoesNegative) {
  const std::string e = error_of(map_text(road(
      "7", 10, "<line/>",
      section("", "          <lane id=\"-1\" type=\"driving\"><width sOffset=\"0\" a=\"1\" b=\"-0.2\"/></lane>\n"))));
  EXPECT_NE(e.find("lane -1 width goes negative"), std::string::npos) << e;
  EXPECT_EQ(e.rfind("bad.xodr:16: road 7 at s=5:", 0), 0u) << e;  // the lane's line
}

TEST(OpenDriveFile, TheProjectsSmallTownJoinsUp) {
  const OdrMap map = read_opendrive(std::string(LIDARLOOP_DATA_DIR) + "/tests/data/opendrive/small_town.xodr");
  ASSERT_EQ(map.roads.size(), 3u);
  EXPECT_TRUE(map.warnings.empty());
  // Each road ends where its successor starts (line, spiral, arc, then a paramPoly3 to a line).
  for (const auto& [a, b] : {std::pair<std::string, std::string>{"1", "2"}, {"2", "3"}}) {
    const OdrRoad& from = *map.road(a);
    const OdrPose end = reference_pose(from, from.length), start = reference_pose(*map.road(b), 0);
    EXPECT_NEAR(end.x, start.x, 1e-3) << a << " -> " << b;
    EXPECT_NEAR(end.y, start.y, 1e-3) << a << " -> " << b;
    EXPECT_NEAR(end.hdg, start.hdg, 1e-6) << a << " -> " << b;
  }
}

TEST(OpenDriveFile, RealMapsFromShared) {
  if (!std::filesystem::exists(kShared + "Town01.xodr")) GTEST_SKIP() << kShared << " not there";
  const OdrMap town = read_opendrive(kShared + "Town01.xodr");
  EXPECT_EQ(town.roads.size(), 98u);
  EXPECT_EQ(town.junctions.size(), 12u);
  EXPECT_TRUE(town.origin_from_map);
  EXPECT_DOUBLE_EQ(town.origin.lat_deg, 49);
  const OdrMap fab = read_opendrive(kShared + "fabriksgatan.xodr");
  EXPECT_EQ(fab.roads.size(), 16u);
  EXPECT_FALSE(fab.origin_from_map);
  const OdrLane* sidewalk = fab.road("0")->sections[0].lane(-3);
  ASSERT_NE(sidewalk, nullptr);
  EXPECT_EQ(sidewalk->type, "sidewalk");
  EXPECT_NEAR(lane_height(*sidewalk, 0, 0), 0.12, 1e-6);
  // Consecutive geometries meet: each starts where the one before ends (the evaluator's end points
  // agree with the file's next start within a millimetre).
  for (const OdrMap* m : {&town, &fab})
    for (const auto& r : m->roads)
      for (size_t i = 1; i < r.plan_view.size(); ++i) {
        const OdrPose end = geometry_pose(r.plan_view[i - 1], r.plan_view[i - 1].length);
        EXPECT_NEAR(end.x, r.plan_view[i].x, 1e-3) << m->file << " road " << r.id;
        EXPECT_NEAR(end.y, r.plan_view[i].y, 1e-3) << m->file << " road " << r.id;
      }
}

}  // namespace
}  // namespace lidarloop
