// The local metric frame (transverse Mercator around the map origin) and the GeoJSON curb map file.
// Known truth comes from GeographicLib's geodesic solver, which is independent of the projection.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>
#include <GeographicLib/Geodesic.hpp>

#include "common/curb_map_file.hpp"
#include "common/geodetic.hpp"
#include "common/input_error.hpp"

namespace lidarloop {
namespace {

constexpr double kMillimetre = 1e-3;
const Geodetic kCampus{31.2856, 121.2147, 4.0};
const Geodetic kSydney{-33.86, 151.21, 0.0};
const Geodetic kUtmBoundary{48.0, 6.0, 0.0};  // lon 6 deg: the boundary between UTM zones 31 and 32

// Distance in metres between two WGS-84 positions, by the geodesic (not the projection under test).
double geodesic_distance(double lat1, double lon1, double lat2, double lon2) {
  double s12 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(lat1, lon1, lat2, lon2, s12);
  return s12;
}

// The WGS-84 position a given distance from `from` along `azimuth_deg` (0 = north, 90 = east).
Geodetic geodesic_direct(const Geodetic& from, double azimuth_deg, double distance_m) {
  Geodetic out;
  GeographicLib::Geodesic::WGS84().Direct(from.lat_deg, from.lon_deg, azimuth_deg, distance_m, out.lat_deg,
                                          out.lon_deg);
  return out;
}

// Local grid -> WGS-84 -> local, and the WGS-84 of each grid node -> local -> WGS-84: both under 1 mm.
void expect_round_trip_on_grid(const Geodetic& origin, double half_x, double half_y, double step) {
  const LocalFrame frame(origin);
  double worst_local = 0, worst_geodetic = 0;
  for (double x = -half_x; x <= half_x + 1e-9; x += step)
    for (double y = -half_y; y <= half_y + 1e-9; y += step) {
      const Eigen::Vector2d xy(x, y);
      const Geodetic g = frame.to_geodetic(xy);
      worst_local = std::max(worst_local, (frame.to_local(g.lat_deg, g.lon_deg) - xy).norm());
      // Start from a geodetic position this time (the same node, so the grid covers the same area).
      const Geodetic back = frame.to_geodetic(frame.to_local(g.lat_deg, g.lon_deg));
      worst_geodetic = std::max(worst_geodetic, geodesic_distance(g.lat_deg, g.lon_deg, back.lat_deg, back.lon_deg));
    }
  EXPECT_LT(worst_local, kMillimetre) << "local -> WGS-84 -> local, origin " << origin.lat_deg << ", "
                                      << origin.lon_deg;
  EXPECT_LT(worst_geodetic, kMillimetre) << "WGS-84 -> local -> WGS-84, origin " << origin.lat_deg << ", "
                                         << origin.lon_deg;
}

// ---------------------------------------------------------------------------------------------- LocalFrame

TEST(Geodetic, OriginMapsToZero) {
  for (const Geodetic& origin : {kCampus, kSydney, kUtmBoundary}) {
    const LocalFrame frame(origin);
    EXPECT_LT(frame.to_local(origin.lat_deg, origin.lon_deg).norm(), 1e-9);
    const Geodetic back = frame.to_geodetic({0, 0});
    EXPECT_NEAR(back.lat_deg, origin.lat_deg, 1e-12);
    EXPECT_NEAR(back.lon_deg, origin.lon_deg, 1e-12);
  }
}

TEST(Geodetic, AltitudeIsPassedThrough) {
  const LocalFrame frame(kCampus);
  EXPECT_EQ(frame.to_geodetic({10, 20}, 42.5).alt_m, 42.5);
  EXPECT_EQ(frame.origin().alt_m, kCampus.alt_m);
}

TEST(Geodetic, RoundTripCampusArea) {
  // The campus-sized area (1800 m x 1200 m, the large world) on a 25 m grid, then +-3 km on 100 m.
  expect_round_trip_on_grid(kCampus, 900, 600, 25);
  expect_round_trip_on_grid(kCampus, 3000, 3000, 100);
}

TEST(Geodetic, RoundTripSouthernHemisphere) {
  expect_round_trip_on_grid(kSydney, 900, 600, 25);
  expect_round_trip_on_grid(kSydney, 3000, 3000, 100);
}

TEST(Geodetic, RoundTripAcrossUtmZoneBoundary) {
  // Points on both sides of lon 6 deg: a per-point UTM zone choice would jump by hundreds of km here.
  expect_round_trip_on_grid(kUtmBoundary, 3000, 3000, 100);
  const LocalFrame frame(kUtmBoundary);
  const Eigen::Vector2d west = frame.to_local(kUtmBoundary.lat_deg, 5.99);
  const Eigen::Vector2d east = frame.to_local(kUtmBoundary.lat_deg, 6.01);
  EXPECT_LT(west.x(), 0);
  EXPECT_GT(east.x(), 0);
  // The projection is symmetric about its central meridian (the origin's): mirror images.
  EXPECT_NEAR(west.x(), -east.x(), kMillimetre);
  EXPECT_NEAR(west.y(), east.y(), kMillimetre);
  // And the two points are as far apart as the geodesic says (scale 1 near the origin).
  EXPECT_NEAR((east - west).norm(), geodesic_distance(kUtmBoundary.lat_deg, 5.99, kUtmBoundary.lat_deg, 6.01),
              kMillimetre);
}

TEST(Geodetic, RoundTripAcrossAntimeridian) {
  // Longitudes jump from +180 to -180 here (Fiji); the local frame must not.
  const Geodetic origin{-17.8, 179.999, 0.0};
  expect_round_trip_on_grid(origin, 3000, 3000, 100);
  const LocalFrame frame(origin);
  const Eigen::Vector2d west = frame.to_local(origin.lat_deg, 179.989);   // 0.01 deg west of the origin
  const Eigen::Vector2d east = frame.to_local(origin.lat_deg, -179.991);  // 0.01 deg east, across 180
  EXPECT_NEAR(west.x(), -east.x(), kMillimetre);
  EXPECT_NEAR(west.y(), east.y(), kMillimetre);
  EXPECT_NEAR(east.x(), geodesic_distance(origin.lat_deg, origin.lon_deg, origin.lat_deg, -179.991), 0.01);
}

TEST(Geodetic, NorthIsMeridianArcLength) {
  // 0.001 deg of latitude north of the origin lies on the central meridian, where the transverse
  // Mercator northing is the meridian arc length: the geodesic distance, to the millimetre.
  constexpr double kDeltaLatDeg = 0.001;
  for (const Geodetic& origin : {kCampus, kSydney, kUtmBoundary}) {
    const LocalFrame frame(origin);
    const Eigen::Vector2d north = frame.to_local(origin.lat_deg + kDeltaLatDeg, origin.lon_deg);
    const double arc = geodesic_distance(origin.lat_deg, origin.lon_deg, origin.lat_deg + kDeltaLatDeg, origin.lon_deg);
    EXPECT_NEAR(north.y(), arc, kMillimetre) << "origin lat " << origin.lat_deg;
    EXPECT_NEAR(north.x(), 0.0, kMillimetre);
    EXPECT_GT(north.y(), 100.0);  // ~111 m: y is north (in the southern hemisphere too)
  }
}

TEST(Geodetic, AxesAreEastAndNorth) {
  // Walk 1 km along each compass direction by the geodesic; the local coordinates must point that way
  // and be 1 km long (the projection's scale error at 1 km from the central meridian is ~1e-8).
  constexpr double kDistance = 1000.0;
  struct Direction {
    double azimuth_deg, x, y;  // unit vector expected in the local frame
  };
  for (const Geodetic& origin : {kCampus, kSydney}) {
    const LocalFrame frame(origin);
    for (const Direction d : {Direction{0, 0, 1}, Direction{90, 1, 0}, Direction{180, 0, -1}, Direction{270, -1, 0}}) {
      const Geodetic p = geodesic_direct(origin, d.azimuth_deg, kDistance);
      const Eigen::Vector2d xy = frame.to_local(p.lat_deg, p.lon_deg);
      EXPECT_NEAR(xy.norm(), kDistance, kMillimetre) << "azimuth " << d.azimuth_deg;
      // Grid north differs from true north by the meridian convergence (~0.3 deg here): allow 1 %.
      EXPECT_NEAR(xy.x() / kDistance, d.x, 0.01) << "azimuth " << d.azimuth_deg << ", origin " << origin.lat_deg;
      EXPECT_NEAR(xy.y() / kDistance, d.y, 0.01) << "azimuth " << d.azimuth_deg << ", origin " << origin.lat_deg;
    }
  }
}

// ---------------------------------------------------------------------------------------------- curb map file

// A file in the temp directory, unique to this process and test, removed at the end.
class TempFile {
 public:
  explicit TempFile(const std::string& stem)
      : path_((std::filesystem::temp_directory_path() /
               ("lidarloop_test_" + stem + "_" + std::to_string(::getpid()) + ".geojson"))
                  .string()) {}
  ~TempFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  const std::string& path() const { return path_; }
  void write(const std::string& text) const { std::ofstream(path_) << text; }

 private:
  std::string path_;
};

// Reading `text` as a curb map must fail with an InputError naming the file and containing `what`.
void expect_curb_map_error(const std::string& stem, const std::string& text, const std::string& what) {
  TempFile file(stem);
  file.write(text);
  try {
    read_curb_map(file.path());
    ADD_FAILURE() << "no error for " << stem;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file.path() + ": ", 0), 0u) << "the message must start with the file: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

// A valid collection around `features`, with the lidarloop.origin foreign member.
std::string collection(const std::string& features) {
  return R"({"type": "FeatureCollection", "lidarloop": {"world": "w", "origin": [121.2147, 31.2856, 4.0]},
            "features": [)" +
         features + "]}";
}

TEST(GeodeticCurbMapFile, WriteReadRoundTrip) {
  CurbMap map;
  map.origin = kCampus;
  map.world = "campus";
  // A closed ring, an open line far from the origin (3 km: projection errors would show), a short one.
  map.curbs.push_back({{0, 0}, {600, 0}, {600, 400}, {0, 400}, {0, 0}});
  map.curbs.push_back({{-3000, 2500}, {-2990.123, 2510.456}, {3000, -3000}});
  map.curbs.push_back({{1.0001, 2.0002}, {1.0101, 2.0002}});
  TempFile file("round_trip");
  write_curb_map(file.path(), map);
  const CurbMap back = read_curb_map(file.path());

  EXPECT_EQ(back.world, map.world);
  EXPECT_DOUBLE_EQ(back.origin.lat_deg, map.origin.lat_deg);
  EXPECT_DOUBLE_EQ(back.origin.lon_deg, map.origin.lon_deg);
  EXPECT_DOUBLE_EQ(back.origin.alt_m, map.origin.alt_m);
  ASSERT_EQ(back.curbs.size(), map.curbs.size());
  for (size_t i = 0; i < map.curbs.size(); ++i) {
    ASSERT_EQ(back.curbs[i].size(), map.curbs[i].size()) << "curb " << i;
    for (size_t k = 0; k < map.curbs[i].size(); ++k)
      EXPECT_LT((back.curbs[i][k] - map.curbs[i][k]).norm(), kMillimetre) << "curb " << i << " point " << k;
  }
}

TEST(GeodeticCurbMapFile, CoordinatesAreLonLatInWgs84) {
  // GeoJSON order is [lon, lat]: a point 0.001 deg north of the origin must come back ~111 m north.
  TempFile file("lon_lat");
  file.write(collection(
      R"({"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
          "coordinates": [[121.2147, 31.2856], [121.2147, 31.2866]]}})"));
  const CurbMap map = read_curb_map(file.path());
  ASSERT_EQ(map.curbs.size(), 1u);
  ASSERT_EQ(map.curbs[0].size(), 2u);
  EXPECT_LT(map.curbs[0][0].norm(), kMillimetre);
  EXPECT_NEAR(map.curbs[0][1].y(), geodesic_distance(31.2856, 121.2147, 31.2866, 121.2147), kMillimetre);
  EXPECT_NEAR(map.curbs[0][1].x(), 0.0, kMillimetre);
}

TEST(GeodeticCurbMapFile, MissingFile) {
  const std::string path = "/nonexistent_dir_lidarloop/curbs.geojson";
  try {
    read_curb_map(path);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
}

TEST(GeodeticCurbMapFile, InvalidJson) {
  expect_curb_map_error("invalid_json", R"({"type": "FeatureCollection", "features": [)", "not valid JSON");
}

// Found by fuzz_hd_map: JSON that parses only up to a number beyond double's range, and members of
// another type than the reader asks value() for, threw nlohmann's own exceptions past the reader.
TEST(GeodeticCurbMapFile, JsonTheReaderCannotUseIsAnInputErrorToo) {
  expect_curb_map_error("huge_number", collection("") + " 1e999999", "not valid JSON");
  expect_curb_map_error("huge_coordinate",
                        collection(R"({"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
                                      "coordinates": [[1e999999, 31.2856], [121.2147, 31.2856]]}})"),
                        "number overflow");
  expect_curb_map_error("type_not_a_string", R"({"type": 7, "features": []})", "not a curb map");
  expect_curb_map_error("geometry_type_not_a_string",
                        collection(R"({"type": "Feature", "properties": {}, "geometry": {"type": 2,
                                      "coordinates": [[121.2147, 31.2856], [121.2148, 31.2856]]}})"),
                        "not a curb map");
}

TEST(GeodeticCurbMapFile, NotAFeatureCollection) {
  expect_curb_map_error("not_collection",
                        R"({"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}})",
                        "not a GeoJSON FeatureCollection");
  expect_curb_map_error("array_document", "[1, 2, 3]", "not a GeoJSON FeatureCollection");
}

TEST(GeodeticCurbMapFile, PointGeometry) {
  expect_curb_map_error("point", collection(R"({"type": "Feature", "properties": {},
                                      "geometry": {"type": "Point", "coordinates": [121.2147, 31.2856]}})"),
                        "feature 0 is not a LineString");
}

TEST(GeodeticCurbMapFile, CoordinatesOutOfRange) {
  expect_curb_map_error("latitude_range",
                        collection(R"({"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
                                      "coordinates": [[121.2147, 31.2856], [121.2147, 95.0]]}})"),
                        "outside WGS-84");
  expect_curb_map_error("longitude_range",
                        collection(R"({"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
                                      "coordinates": [[181.5, 31.2856], [121.2147, 31.2856]]}})"),
                        "outside WGS-84");
}

TEST(GeodeticCurbMapFile, MissingOrigin) {
  expect_curb_map_error("no_origin",
                        R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
                            "geometry": {"type": "LineString", "coordinates": [[121.2, 31.2], [121.3, 31.3]]}}]})",
                        "missing lidarloop.origin");
}

TEST(GeodeticCurbMapFile, OriginOutOfRange) {
  expect_curb_map_error("origin_range",
                        R"({"type": "FeatureCollection", "lidarloop": {"origin": [121.2147, 95.0, 0]},
                            "features": [{"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
                            "coordinates": [[121.2147, 31.2856], [121.2148, 31.2857]]}}]})",
                        "origin");
}

}  // namespace
}  // namespace lidarloop
