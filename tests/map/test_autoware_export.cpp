// `lidarloop map --export autoware` on the 100 m road of tests/data (its map builds in seconds): the
// Lanelet2 map read back with libosmium, an independent OSM reader, against the map's GeoJSON curbs and
// the world; the point cloud map's PCD header and a surface of the world in it.
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <osmium/handler.hpp>
#include <osmium/io/reader.hpp>
#include <osmium/io/xml_input.hpp>
#include <osmium/visitor.hpp>

#include "common/little_endian.hpp"
#include "mapping/autoware_export.hpp"
#include "mapping/map_cache.hpp"
#include "sim/polyline.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

using Tags = std::map<std::string, std::string>;

struct OsmNode {
  double lat = 0, lon = 0;
  Tags tags;
};
struct OsmWay {
  std::vector<int64_t> nodes;
  Tags tags;
};
struct OsmMember {
  char type;  // 'n', 'w', 'r'
  int64_t ref;
  std::string role;
};
struct OsmRelation {
  std::vector<OsmMember> members;
  Tags tags;
};

struct OsmMap : osmium::handler::Handler {
  std::map<int64_t, OsmNode> nodes;
  std::map<int64_t, OsmWay> ways;
  std::map<int64_t, OsmRelation> relations;

  static Tags tags_of(const osmium::OSMObject& o) {
    Tags t;
    for (const osmium::Tag& tag : o.tags()) t[tag.key()] = tag.value();
    return t;
  }
  void node(const osmium::Node& n) { nodes[n.id()] = {n.location().lat(), n.location().lon(), tags_of(n)}; }
  void way(const osmium::Way& w) {
    OsmWay out{{}, tags_of(w)};
    for (const osmium::NodeRef& r : w.nodes()) out.nodes.push_back(r.ref());
    ways[w.id()] = out;
  }
  void relation(const osmium::Relation& r) {
    OsmRelation out{{}, tags_of(r)};
    for (const osmium::RelationMember& m : r.members())
      out.members.push_back({osmium::item_type_to_char(m.type()), m.ref(), m.role()});
    relations[r.id()] = out;
  }
};

OsmMap read_osm(const std::string& path) {
  OsmMap osm;
  osmium::io::Reader reader(path);
  osmium::apply(reader, osm);
  reader.close();
  return osm;
}

class AutowareExport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = std::string(LIDARLOOP_DATA_DIR) + "/tests/data/short_road_world.yaml";
    map_ = ensure_map(world_, options_, false).dir;
    // A folder of this process's own: ctest runs each test case as a process, two at a time.
    out_ =
        (std::filesystem::temp_directory_path() / ("lidarloop_autoware_export_" + std::to_string(::getpid()))).string();
    std::filesystem::remove_all(out_);
    summary_ = export_autoware_map(world_, options_, map_, out_);
    osm_ = read_osm(out_ + "/" + kAutowareLanelet2File);
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(out_); }

  Eigen::Vector2d local_of(const OsmNode& n) const {
    return LocalFrame(read_curb_map(map_ + "/curbs.geojson").origin).to_local(n.lat, n.lon);
  }
  std::vector<const OsmRelation*> lanelets(const std::string& subtype) const {
    std::vector<const OsmRelation*> out;
    for (const auto& [id, r] : osm_.relations)
      if (r.tags.at("type") == "lanelet" && r.tags.at("subtype") == subtype) out.push_back(&r);
    return out;
  }
  static const OsmWay& member_way(const OsmRelation& r, const std::string& role) {
    const auto m = std::find_if(r.members.begin(), r.members.end(), [&](const OsmMember& m) { return m.role == role; });
    EXPECT_NE(m, r.members.end()) << "no member '" << role << "'";
    return osm_.ways.at(m->ref);
  }
  double mean_y(const OsmWay& w) const {
    double y = 0;
    for (const int64_t n : w.nodes) y += local_of(osm_.nodes.at(n)).y();
    return y / double(w.nodes.size());
  }

  static inline MappingOptions options_;
  static inline std::string world_, map_, out_;
  static inline AutowareExportSummary summary_;
  static inline OsmMap osm_;
};

double distance_to(const Polyline2d& line, const Eigen::Vector2d& p) {
  return (sample_polyline(line, project_onto_polyline(line, p)).point - p).norm();
}

constexpr double kCurbTolerance = 0.01;  // m: the brief's 1 cm

// Each curbstone lies on a curb of the GeoJSON map and each GeoJSON curb is a curbstone, one for one.
TEST_F(AutowareExport, CurbstonesAreTheGeoJsonCurbs) {
  const CurbMap curbs = read_curb_map(map_ + "/curbs.geojson");
  std::vector<Polyline2d> stones;
  std::vector<std::string> subtypes;
  for (const auto& [id, w] : osm_.ways)
    if (w.tags.at("type") == "curbstone") {
      Polyline2d line;
      for (const int64_t n : w.nodes) line.push_back(local_of(osm_.nodes.at(n)));
      stones.push_back(line);
      subtypes.push_back(w.tags.at("subtype"));
    }
  ASSERT_FALSE(curbs.curbs.empty());
  ASSERT_EQ(stones.size(), curbs.curbs.size());
  EXPECT_EQ(summary_.lanelet2.curbstones, curbs.curbs.size());
  for (size_t i = 0; i < stones.size(); ++i) {
    // The curb this stone lies on: the one nearest its middle vertex.
    size_t best = 0;
    const Eigen::Vector2d mid = stones[i][stones[i].size() / 2];
    for (size_t c = 0; c < curbs.curbs.size(); ++c)
      if (distance_to(curbs.curbs[c], mid) < distance_to(curbs.curbs[best], mid)) best = c;
    for (const Eigen::Vector2d& p : stones[i]) EXPECT_LE(distance_to(curbs.curbs[best], p), kCurbTolerance);
    for (const Eigen::Vector2d& p : curbs.curbs[best]) EXPECT_LE(distance_to(stones[i], p), kCurbTolerance);
    EXPECT_EQ(subtypes[i], curbs.kinds[best] == "vertical" ? "high" : "low") << curbs.kinds[best];
  }
}

// Every lanelet has a left and a right bound, and a road lanelet's left is on the left of its direction of
// travel (right-hand traffic on the road along +x: the lane south of the centreline goes east).
TEST_F(AutowareExport, LaneletsHaveBoundsOnTheirSides) {
  for (const auto& [id, r] : osm_.relations) {
    if (r.tags.at("type") != "lanelet") continue;
    for (const char* role : {"left", "right"}) {
      EXPECT_EQ(std::count_if(r.members.begin(), r.members.end(), [&](const OsmMember& m) { return m.role == role; }),
                1)
          << "lanelet " << id << " " << role;
      for (const OsmMember& m : r.members) {
        if (m.role != role) continue;
        EXPECT_TRUE(m.type == 'w' && osm_.ways.count(m.ref)) << "lanelet " << id << " " << role;
      }
    }
  }
  const auto roads = lanelets("road");
  ASSERT_EQ(roads.size(), 2u);  // two lanes, one each way
  EXPECT_EQ(summary_.lanelet2.road_lanelets, 2u);
  for (const OsmRelation* r : roads) {
    const double left = mean_y(member_way(*r, "left")), right = mean_y(member_way(*r, "right"));
    EXPECT_NEAR(left, 0.0, 0.1);             // the centre line (the survey moves it by cm)
    EXPECT_NEAR(std::abs(right), 4.0, 0.1);  // the curb, 8 m road
    EXPECT_EQ(member_way(*r, "left").tags.at("subtype"), "dashed");
    EXPECT_EQ(member_way(*r, "right").tags.at("type"), "road_border");
    EXPECT_EQ(r->tags.at("one_way"), "yes");
  }
}

// The crosswalk at 50 m: its lanelet, polygon and regulatory element, with two stop lines derived in front
// of it (the world has none) and both road lanelets referring to it.
TEST_F(AutowareExport, CrosswalkHasItsRegulatoryElement) {
  ASSERT_EQ(lanelets("crosswalk").size(), 1u);
  EXPECT_EQ(summary_.lanelet2.stop_lines, 0u);
  EXPECT_EQ(summary_.lanelet2.derived_stop_lines, 2u);
  int64_t element = 0;
  for (const auto& [id, r] : osm_.relations)
    if (r.tags.at("type") == "regulatory_element" && r.tags.at("subtype") == "crosswalk") element = id;
  ASSERT_NE(element, 0);
  std::map<std::string, int> roles;
  for (const OsmMember& m : osm_.relations.at(element).members) {
    ++roles[m.role];
    if (m.role == "ref_line") {
      const OsmWay& stop = osm_.ways.at(m.ref);
      EXPECT_EQ(stop.tags.at("type"), "stop_line");
      // 3.5 m before the crosswalk's near edge (48 m or 52 m): x 44.5 or 55.5.
      const double x = local_of(osm_.nodes.at(stop.nodes.front())).x();
      EXPECT_NEAR(std::abs(x - 50.0), 5.5, 0.1);
    }
  }
  EXPECT_EQ(roles["refers"], 1);
  EXPECT_EQ(roles["crosswalk_polygon"], 1);
  EXPECT_EQ(roles["ref_line"], 2);
  for (const OsmRelation* r : lanelets("road"))
    EXPECT_TRUE(std::any_of(r->members.begin(), r->members.end(),
                            [&](const OsmMember& m) { return m.role == "regulatory_element" && m.ref == element; }));
}

// local_x/local_y and lat/lon are the same place through the projection: lat/lon are the local metres'
// latitude and longitude rounded to OSM's 1e-7 degrees, and every node has its elevation.
TEST_F(AutowareExport, LocalAndGeodeticAgree) {
  const LocalFrame frame(read_curb_map(map_ + "/curbs.geojson").origin);
  constexpr double kHalfUnit = 0.5e-7 + 1e-12;  // degrees: osmium::Location's rounding
  ASSERT_GT(osm_.nodes.size(), 100u);
  EXPECT_EQ(summary_.lanelet2.nodes, osm_.nodes.size());
  double worst_m = 0;
  for (const auto& [id, n] : osm_.nodes) {
    const Eigen::Vector2d local(std::stod(n.tags.at("local_x")), std::stod(n.tags.at("local_y")));
    const Geodetic g = frame.to_geodetic(local);
    EXPECT_LE(std::abs(n.lat - g.lat_deg), kHalfUnit);
    EXPECT_LE(std::abs(n.lon - g.lon_deg), kHalfUnit);
    worst_m = std::max(worst_m, (frame.to_local(n.lat, n.lon) - local).norm());
    EXPECT_TRUE(n.tags.count("ele"));
  }
  EXPECT_LT(worst_m, 0.0075);  // 1e-7 degrees is at most 5.6 mm of latitude and 4.8 mm of longitude here
  std::cout << "worst lat/lon vs local_x/local_y: " << worst_m * 1000 << " mm\n";
}

TEST_F(AutowareExport, ProjectorInfoNamesTheOrigin) {
  std::ifstream in(out_ + "/" + kAutowareProjectorFile);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("projector_type: TransverseMercator\n"), std::string::npos);
  EXPECT_NE(text.str().find("scale_factor: 1.0\n"), std::string::npos);
  EXPECT_NE(text.str().find("  latitude: 31.28\n"), std::string::npos);
  EXPECT_NE(text.str().find("  longitude: 121.21\n"), std::string::npos);
}

// The PCD header is what PCL reads, POINTS matches the file's size, and the road surface is where the
// world puts it: the points above the carriageway's middle lie on the pavement (the crown's top, z 0).
TEST_F(AutowareExport, PointCloudHasTheRoad) {
  std::ifstream in(out_ + "/" + kAutowarePointCloudFile, std::ios::binary);
  std::stringstream whole;
  whole << in.rdbuf();
  const std::string bytes = whole.str();
  const size_t data = bytes.find("DATA binary\n");
  ASSERT_NE(data, std::string::npos);
  const std::string head = bytes.substr(0, data);
  EXPECT_NE(head.find("\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"), std::string::npos);
  const size_t points_at = head.find("\nPOINTS ");
  ASSERT_NE(points_at, std::string::npos);
  const size_t points = std::stoul(head.substr(points_at + 8));
  EXPECT_EQ(points, summary_.points);
  const size_t body = data + std::strlen("DATA binary\n");
  ASSERT_EQ(bytes.size(), body + points * 16);

  std::vector<float> road_z;
  size_t with_intensity = 0;
  for (size_t i = 0; i < points; ++i) {
    float v[4];
    for (int k = 0; k < 4; ++k) {
      const uint32_t u = uint32_t(get_le(bytes.data() + body + i * 16 + size_t(k) * 4, 4));
      std::memcpy(&v[k], &u, 4);
    }
    if (v[0] > 10 && v[0] < 90 && std::abs(v[1]) < 0.5 && v[2] < 1.0) {
      road_z.push_back(v[2]);
      with_intensity += v[3] > 0;
    }
  }
  ASSERT_GT(road_z.size(), 100u);
  std::nth_element(road_z.begin(), road_z.begin() + long(road_z.size() / 2), road_z.end());
  EXPECT_NEAR(road_z[road_z.size() / 2], 0.0, 0.02);
  std::cout << "median z of " << road_z.size() << " points over the road's middle: " << road_z[road_z.size() / 2]
            << " m\n";
  EXPECT_GT(double(with_intensity), 0.9 * double(road_z.size()));
}

// A side road meeting the main road in a T (the world alone, no survey): where an edge of a road opens
// into the other road its bound is virtual, elsewhere road_border, and the lanelets there go straight.
TEST(Lanelet2Map, JunctionMouthsAreVirtual) {
  const LoadedWorld w = load_world(std::string(LIDARLOOP_DATA_DIR) + "/tests/data/t_junction_world.yaml");
  const std::string path =
      (std::filesystem::temp_directory_path() / ("lidarloop_t_junction_" + std::to_string(::getpid()) + ".osm"))
          .string();
  const Lanelet2Summary summary =
      write_lanelet2_map(path, w.description, w.world, w.world.curb_map(), [](const Polyline2d& l) { return l; });
  const OsmMap osm = read_osm(path);
  std::filesystem::remove(path);
  const LocalFrame frame(w.description.origin);
  std::vector<Polyline2d> virtual_lines;
  size_t borders = 0;
  for (const auto& [id, way] : osm.ways) {
    if (way.tags.at("type") == "road_border") ++borders;
    if (way.tags.at("type") != "virtual") continue;
    Polyline2d line;
    for (const int64_t n : way.nodes) line.push_back(frame.to_local(osm.nodes.at(n).lat, osm.nodes.at(n).lon));
    virtual_lines.push_back(line);
  }
  // Main: three pieces, the middle one open on its north edge; side: two pieces, the first (inside the
  // main road's carriageway) open on both edges.
  EXPECT_EQ(summary.road_lanelets, 2u * 3 + 2u * 2);
  EXPECT_EQ(summary.intersection_lanelets, 2u + 2u);
  EXPECT_EQ(borders, 5u + 2u);
  ASSERT_EQ(virtual_lines.size(), 3u);
  size_t across_mouth = 0;
  for (const Polyline2d& line : virtual_lines) {
    const auto [lo, hi] = std::minmax({line.front().x(), line.back().x()});
    // The main road's north edge (y 4) across the side road's carriageway (x 46-54) and its corners.
    if (std::abs(line.front().y() - 4.0) < 0.01 && lo < 46 && hi > 54) ++across_mouth;
  }
  EXPECT_EQ(across_mouth, 1u);
  size_t straight = 0;
  for (const auto& [id, r] : osm.relations)
    straight += r.tags.count("turn_direction") && r.tags.at("turn_direction") == "straight";
  EXPECT_EQ(straight, summary.intersection_lanelets);
}

}  // namespace
}  // namespace lidarloop
