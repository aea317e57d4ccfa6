// `lidarloop map --export autoware` on the 100 m road of tests/data (its map builds in seconds): the
// Lanelet2 map read back with the project's reader (sim/lanelet2_file.hpp) against the map's GeoJSON
// curbs and the world, routed on with the lane graph (sim/lane_graph.hpp), and built back into a world
// (sim/lanelet2_world.hpp); the point cloud map's PCD header and a surface of the world in it. The
// junctions' lanelets on the T-junction of tests/data and on the campus (their worlds alone, no survey).
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include "common/little_endian.hpp"
#include "mapping/autoware_export.hpp"
#include "mapping/map_cache.hpp"
#include "sim/lane_graph.hpp"
#include "sim/lanelet2_file.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/polyline.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

Polyline2d planar(const std::vector<Eigen::Vector3d>& points) {
  Polyline2d out;
  for (const Eigen::Vector3d& p : points) out.push_back(p.head<2>());
  return out;
}

double distance_to(const Polyline2d& line, const Eigen::Vector2d& p) {
  return (sample_polyline(line, project_onto_polyline(line, p)).point - p).norm();
}

std::string tag(const Lanelet2Tags& tags, const std::string& key) {
  const auto it = tags.find(key);
  return it == tags.end() ? "" : it->second;
}

// Whether p is inside the lanelet's polygon (left bound, then the right bound backwards): even-odd rule.
bool inside(const Lanelet2Lanelet& l, const Eigen::Vector2d& p) {
  Polyline2d ring = planar(l.left_points);
  const Polyline2d right = planar(l.right_points);
  ring.insert(ring.end(), right.rbegin(), right.rend());
  bool in = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
    if ((ring[i].y() > p.y()) != (ring[j].y() > p.y()) &&
        p.x() < (ring[j].x() - ring[i].x()) * (p.y() - ring[i].y()) / (ring[j].y() - ring[i].y()) + ring[i].x())
      in = !in;
  return in;
}

// What every export should satisfy, whatever the world: MetaInfo, lane_change on every lane bound (dashed
// yes, solid and road_border no), ele the origin's altitude plus the pavement's height.
void expect_autoware_conventions(const std::string& osm_path, const Lanelet2Map& map, const Geodetic& origin,
                                 const GroundHeight& pavement) {
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(osm_path.c_str()));
  const pugi::xml_node meta = doc.child("osm").child("MetaInfo");
  ASSERT_TRUE(meta) << "no MetaInfo";
  EXPECT_STREQ(meta.attribute("format_version").value(), "1.0");
  EXPECT_STRNE(meta.attribute("map_version").value(), "");
  EXPECT_STREQ(doc.child("osm").first_child().name(), "MetaInfo");
  size_t bounds = 0;
  for (const Lanelet2Lanelet& l : map.lanelets) {
    if (l.subtype != "road") continue;
    for (const Lanelet2Id id : {l.left, l.right}) {
      const Lanelet2LineString& line = *map.line(id);
      const std::string change = tag(line.tags, "lane_change");
      EXPECT_TRUE(change == "yes" || change == "no") << "way " << id << " (" << line.type << ")";
      if (line.subtype == "dashed") {
        EXPECT_EQ(change, "yes") << "way " << id;
      }
      if (line.subtype == "solid" || line.type == "road_border") {
        EXPECT_EQ(change, "no") << "way " << id;
      }
      ++bounds;
    }
  }
  EXPECT_GT(bounds, 0u);
  double worst = 0;
  for (const auto& [id, line] : map.lines)
    for (const Eigen::Vector3d& p : line.points)
      worst = std::max(worst, std::abs(p.z() - (origin.alt_m + pavement(p.head<2>()))));
  EXPECT_LT(worst, 0.01) << "ele is the origin's altitude plus the pavement's height";
}

// The routing check an Autoware user would run: every drivable lanelet reaches every other.
void expect_one_strong_component(const Lanelet2Map& map, const std::string& what) {
  const LaneGraph graph = build_lane_graph(map);
  const LaneGraphComponents c = lane_graph_components(graph);
  std::cout << "[ figures  ] " << what << ": " << describe_components(c) << "\n";
  ASSERT_FALSE(graph.nodes.empty());
  EXPECT_EQ(c.strong_sizes.size(), 1u);
  EXPECT_EQ(c.weak_sizes.size(), 1u);
  for (LaneGraphNodeId n = 0; n < LaneGraphNodeId(graph.nodes.size()); ++n)
    EXPECT_EQ(reachable_from(graph, n).size(), graph.nodes.size()) << "from " << describe_node(graph, n);
  for (const LaneGraphNode& n : graph.nodes) EXPECT_GE(n.length, 3.0) << "a sliver: lanelet " << n.lanelet;
}

// Export then import gives back the world: every curb line of `curbs` (sampled every 0.5 m) within 2 cm
// of a curb of the imported world, each road's lanes across it between junctions, every crosswalk and
// stop line.
void expect_round_trip(const Lanelet2Map& map, const WorldDescription& world, const CurbMap& curbs,
                       const MaterialTable& materials, const Lanelet2Summary& summary) {
  Lanelet2BuildReport report;
  const World back = build_lanelet2_world(map, Lanelet2WorldParams(), materials,
                                          std::string(LIDARLOOP_DATA_DIR) + "/assets/actors", &report);
  ASSERT_EQ(back.curbs.size(), curbs.curbs.size());
  double worst = 0;
  size_t samples = 0;
  for (const Polyline2d& curb : curbs.curbs) {
    const double length = polyline_length(curb);
    for (double s = 0; s <= length; s += 0.5, ++samples) {
      const Eigen::Vector2d p = sample_polyline(curb, s).point;
      double nearest = 1e9;
      for (const Polyline2d& c : back.curbs) nearest = std::min(nearest, distance_to(c, p));
      worst = std::max(worst, nearest);
    }
  }
  std::cout << "[ figures  ] round trip: " << samples << " curb samples, farthest " << worst * 1000
            << " mm from the imported curbs\n";
  EXPECT_LT(worst, 0.02);

  // Lanes: across every road each 5 m, the lane centres lie in as many distinct road lanelets as the road
  // has lanes, away from junctions (where a connecting lanelet covers a lane centre).
  size_t sections = 0;
  for (const RoadSpec& road : world.roads) {
    const double length = polyline_length(road.centreline);
    for (double s = 2.5; s < length; s += 5) {
      const PolylineSample at = sample_polyline(road.centreline, s);
      const Eigen::Vector2d normal(-at.tangent.y(), at.tangent.x());
      std::vector<Eigen::Vector2d> centres;
      for (int j = 0; j < road.lanes; ++j)
        centres.push_back(at.point + normal * (-road.width / 2 + (j + 0.5) * road.width / road.lanes));
      bool junction = false;
      std::vector<std::set<Lanelet2Id>> in(centres.size());
      for (const Lanelet2Lanelet& l : map.lanelets) {
        if (l.subtype != "road") continue;
        for (size_t j = 0; j < centres.size(); ++j)
          if (inside(l, centres[j])) {
            if (l.tags.count("turn_direction")) junction = true;
            in[j].insert(l.id);
          }
      }
      if (junction) continue;
      ++sections;
      std::set<Lanelet2Id> all;
      for (size_t j = 0; j < centres.size(); ++j) {
        EXPECT_EQ(in[j].size(), 1u) << road.name << " at " << s << " m, lane " << j;
        all.insert(in[j].begin(), in[j].end());
      }
      EXPECT_EQ(all.size(), size_t(road.lanes)) << road.name << " at " << s << " m";
    }
  }
  EXPECT_GT(sections, 10u);
  size_t crosswalks = 0;
  for (const Lanelet2Lanelet& l : map.lanelets) crosswalks += l.subtype == "crosswalk";
  EXPECT_EQ(crosswalks, world.crosswalks.size());
  EXPECT_EQ(size_t(report.stop_lines), world.stop_lines.size() + summary.derived_stop_lines);
  EXPECT_EQ(size_t(report.pedestrian_markings), 2 * world.crosswalks.size());
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
    // With map_projector_info.yaml beside it: local_x / local_y through the TransverseMercator projector.
    map_l2_ = read_lanelet2(osm_path());
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(out_); }

  static std::string osm_path() { return out_ + "/" + kAutowareLanelet2File; }
  std::vector<const Lanelet2Lanelet*> lanelets(const std::string& subtype) const {
    std::vector<const Lanelet2Lanelet*> out;
    for (const Lanelet2Lanelet& l : map_l2_.lanelets)
      if (l.subtype == subtype) out.push_back(&l);
    return out;
  }
  static double mean_y(const Lanelet2LineString& w) {
    double y = 0;
    for (const Eigen::Vector3d& p : w.points) y += p.y();
    return y / double(w.points.size());
  }

  static inline MappingOptions options_;
  static inline std::string world_, map_, out_;
  static inline AutowareExportSummary summary_;
  static inline Lanelet2Map map_l2_;
};

constexpr double kCurbTolerance = 0.01;  // m: the brief's 1 cm

// Each curbstone lies on a curb of the GeoJSON map and each GeoJSON curb is a curbstone, one for one.
TEST_F(AutowareExport, CurbstonesAreTheGeoJsonCurbs) {
  const CurbMap curbs = read_curb_map(map_ + "/curbs.geojson");
  std::vector<Polyline2d> stones;
  std::vector<std::string> subtypes;
  for (const auto& [id, w] : map_l2_.lines)
    if (w.type == "curbstone") {
      stones.push_back(planar(w.points));
      subtypes.push_back(w.subtype);
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

// A road lanelet's left is on the left of its direction of travel (right-hand traffic on the road along
// +x: the lane south of the centreline goes east), and its speed limit is the road's design speed.
TEST_F(AutowareExport, LaneletsHaveBoundsOnTheirSides) {
  const auto roads = lanelets("road");
  ASSERT_EQ(roads.size(), 2u);  // two lanes, one each way
  EXPECT_EQ(summary_.lanelet2.road_lanelets, 2u);
  EXPECT_EQ(summary_.lanelet2.junctions, 0u);
  const LoadedWorld w = load_world(world_);
  for (const Lanelet2Lanelet* r : roads) {
    const Lanelet2LineString &left = *map_l2_.line(r->left), &right = *map_l2_.line(r->right);
    EXPECT_NEAR(mean_y(left), 0.0, 0.1);             // the centre line (the survey moves it by cm)
    EXPECT_NEAR(std::abs(mean_y(right)), 4.0, 0.1);  // the curb, 8 m road
    EXPECT_EQ(left.subtype, "dashed");
    EXPECT_EQ(right.type, "road_border");
    EXPECT_TRUE(r->one_way);
    ASSERT_TRUE(r->speed_limit_mps);
    EXPECT_NEAR(*r->speed_limit_mps * 3.6, w.description.roads.front().design_speed, 1e-9);
  }
}

// The crosswalk at 50 m: its lanelet, polygon and regulatory element, with two stop lines derived in front
// of it (the world has none) and both road lanelets referring to it.
TEST_F(AutowareExport, CrosswalkHasItsRegulatoryElement) {
  ASSERT_EQ(lanelets("crosswalk").size(), 1u);
  EXPECT_EQ(summary_.lanelet2.stop_lines, 0u);
  EXPECT_EQ(summary_.lanelet2.derived_stop_lines, 2u);
  const Lanelet2Regulatory* element = nullptr;
  for (const Lanelet2Regulatory& r : map_l2_.regulatory)
    if (r.subtype == "crosswalk") element = &r;
  ASSERT_NE(element, nullptr);
  ASSERT_EQ(element->members.count("ref_line"), 1u);
  EXPECT_EQ(element->members.at("ref_line").size(), 2u);
  for (const Lanelet2Id id : element->members.at("ref_line")) {
    const Lanelet2LineString& stop = *map_l2_.line(id);
    EXPECT_EQ(stop.type, "stop_line");
    // 3.5 m before the crosswalk's near edge (48 m or 52 m): x 44.5 or 55.5.
    EXPECT_NEAR(std::abs(stop.points.front().x() - 50.0), 5.5, 0.1);
  }
  EXPECT_EQ(element->members.at("refers").size(), 1u);
  EXPECT_EQ(element->members.at("crosswalk_polygon").size(), 1u);
  for (const Lanelet2Lanelet* r : lanelets("road"))
    EXPECT_NE(std::find(r->regulatory_elements.begin(), r->regulatory_elements.end(), element->id),
              r->regulatory_elements.end());
}

// local_x/local_y and lat/lon are the same place through the projection, to well under a millimetre (lat
// and lon are written as the exact doubles), and every node has its elevation.
TEST_F(AutowareExport, LocalAndGeodeticAgree) {
  const LocalFrame frame(read_curb_map(map_ + "/curbs.geojson").origin);
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(osm_path().c_str()));
  size_t nodes = 0;
  double worst_m = 0;
  for (const pugi::xml_node n : doc.child("osm").children("node")) {
    std::map<std::string, std::string> tags;
    for (const pugi::xml_node t : n.children("tag")) tags[t.attribute("k").value()] = t.attribute("v").value();
    const Eigen::Vector2d local(std::stod(tags.at("local_x")), std::stod(tags.at("local_y")));
    const double lat = n.attribute("lat").as_double(), lon = n.attribute("lon").as_double();
    const Geodetic g = frame.to_geodetic(local);
    EXPECT_LE(std::abs(lat - g.lat_deg), 1e-12);
    EXPECT_LE(std::abs(lon - g.lon_deg), 1e-12);
    worst_m = std::max(worst_m, (frame.to_local(lat, lon) - local).norm());
    EXPECT_TRUE(tags.count("ele"));
    ++nodes;
  }
  ASSERT_GT(nodes, 100u);
  EXPECT_EQ(summary_.lanelet2.nodes, nodes);
  EXPECT_LT(worst_m, 1e-4);
  std::cout << "worst lat/lon vs local_x/local_y: " << worst_m * 1000 << " mm\n";
}

TEST_F(AutowareExport, ProjectorInfoNamesTheOrigin) {
  std::ifstream in(out_ + "/" + kAutowareProjectorFile);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("projector_type: TransverseMercator\n"), std::string::npos);
  EXPECT_NE(text.str().find("vertical_datum: WGS84\n"), std::string::npos);
  EXPECT_NE(text.str().find("scale_factor: 1.0\n"), std::string::npos);
  EXPECT_NE(text.str().find("  latitude: 31.28\n"), std::string::npos);
  EXPECT_NE(text.str().find("  longitude: 121.21\n"), std::string::npos);
  EXPECT_EQ(map_l2_.coordinates, Lanelet2Coordinates::transverse_mercator);
}

TEST_F(AutowareExport, MetaInfoLaneChangeAndHeights) {
  const LoadedWorld w = load_world(world_);
  expect_autoware_conventions(osm_path(), map_l2_, w.description.origin, w.world.pavement());
}

// Export then import: the imported world's curbs are the survey's (the exported curbstones are the
// surveyed curb map, curbs.geojson, not the world's exact curbs), the lanes, crosswalk and stop lines.
TEST_F(AutowareExport, RoundTripGivesBackTheWorld) {
  const LoadedWorld w = load_world(world_);
  expect_round_trip(map_l2_, w.description, read_curb_map(map_ + "/curbs.geojson"), w.materials, summary_.lanelet2);
}

// The PCD header is what PCL reads, POINTS matches the file's size, and the road surface is where the
// world puts it: the points above the carriageway's middle lie on the pavement (the crown's top, z 0 above
// the origin, whose altitude z adds: the WGS-84 height the projector file declares).
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

  const double alt = read_curb_map(map_ + "/curbs.geojson").origin.alt_m;
  std::vector<float> road_z;
  size_t with_intensity = 0;
  for (size_t i = 0; i < points; ++i) {
    float v[4];
    for (int k = 0; k < 4; ++k) {
      const uint32_t u = uint32_t(get_le(bytes.data() + body + i * 16 + size_t(k) * 4, 4));
      std::memcpy(&v[k], &u, 4);
    }
    if (v[0] > 10 && v[0] < 90 && std::abs(v[1]) < 0.5 && v[2] - alt < 1.0) {
      road_z.push_back(v[2]);
      with_intensity += v[3] > 0;
    }
  }
  ASSERT_GT(road_z.size(), 100u);
  std::nth_element(road_z.begin(), road_z.begin() + long(road_z.size() / 2), road_z.end());
  EXPECT_NEAR(road_z[road_z.size() / 2], alt, 0.02);
  std::cout << "median z of " << road_z.size() << " points over the road's middle: " << road_z[road_z.size() / 2]
            << " m\n";
  EXPECT_GT(double(with_intensity), 0.9 * double(road_z.size()));
}

// A world's map written alone (no survey: the world's own lines) into a temporary file and read back.
struct Written {
  LoadedWorld world;
  Lanelet2Summary summary;
  Lanelet2Map map;
  std::string path;
};
Written write_world_map(const std::string& world, const std::function<void(LoadedWorld&)>& change = {}) {
  Written out{load_world(world), {}, {}, {}};
  if (change) change(out.world);
  out.path = (std::filesystem::temp_directory_path() /
              ("lidarloop_l2_" + out.world.description.name + "_" + std::to_string(::getpid()) + ".osm"))
                 .string();
  out.summary = write_lanelet2_map(out.path, out.world.description, out.world.world, out.world.world.curb_map(),
                                   [](const Polyline2d& l) { return l; });
  Lanelet2ReadOptions options;
  options.origin = out.world.description.origin;
  out.map = read_lanelet2(out.path, options);
  return out;
}

// A side road meeting the main road in a T. The main road is cut at the junction's mouths only (no
// slivers) and keeps its lanes straight through, bounded by a road_border along its closed south edge and
// a virtual line across the side road's mouth; the side road ends at its mouth; four lanelets turn
// (left and right, in and out of the side road), their ends the lanes' ends. Heights with the origin's
// altitude, speed limits from each road's design speed.
TEST(Lanelet2Map, TJunctionTurnsEveryWay) {
  Written t =
      write_world_map(std::string(LIDARLOOP_DATA_DIR) + "/tests/data/t_junction_world.yaml", [](LoadedWorld& w) {
        w.description.origin.alt_m = 123.25;  // heights are WGS-84: the origin's altitude plus the local z
        w.description.roads[1].design_speed = 50;
      });
  const Lanelet2Summary& summary = t.summary;
  EXPECT_EQ(summary.junctions, 1u);
  EXPECT_EQ(summary.road_lanelets, 2u * 3 + 2u * 1 + 4u);
  EXPECT_EQ(summary.intersection_lanelets, 2u + 4u);
  EXPECT_EQ(summary.turn_lanelets, 4u);
  EXPECT_EQ(summary.short_lanelets, 0u);
  std::map<std::string, int> turns, types;
  for (const Lanelet2Lanelet& l : t.map.lanelets)
    if (l.tags.count("turn_direction")) ++turns[l.tags.at("turn_direction")];
  EXPECT_EQ(turns, (std::map<std::string, int>{{"left", 2}, {"right", 2}, {"straight", 2}}));
  std::vector<Polyline2d> virtual_lines;
  for (const auto& [id, way] : t.map.lines) {
    ++types[way.type];
    if (way.type == "virtual") virtual_lines.push_back(planar(way.points));
  }
  EXPECT_EQ(types["road_border"], 2 + 1 + 2 + 2);  // west, through (south only), east, side
  EXPECT_EQ(types["virtual"], 2 + 4 * 2);          // through (north edge, centre), the turns' bounds
  size_t across_mouth = 0;
  for (const Polyline2d& line : virtual_lines) {
    const auto [lo, hi] = std::minmax({line.front().x(), line.back().x()});
    // The main road's north edge (y 4) across the side road's carriageway (x 46-54) and its corners.
    if (std::abs(line.front().y() - 4.0) < 0.01 && std::abs(line.back().y() - 4.0) < 0.01 && lo < 46 && hi > 54)
      ++across_mouth;
  }
  EXPECT_EQ(across_mouth, 1u);
  for (const Lanelet2Lanelet& l : t.map.lanelets) {
    if (l.subtype != "road" || l.tags.count("turn_direction")) continue;
    const bool side = l.left_points.front().x() > 45 && l.left_points.front().x() < 55 && l.left_points.front().y() > 5;
    ASSERT_TRUE(l.speed_limit_mps);
    EXPECT_NEAR(*l.speed_limit_mps * 3.6, side ? 50 : 30, 1e-9) << "lanelet " << l.id;
  }
  expect_autoware_conventions(t.path, t.map, t.world.description.origin, t.world.world.pavement());
  std::filesystem::remove(t.path);

  // Every way into the junction leads out by the two other arms: a car arriving on any lane reaches the
  // lanes leaving by the other roads (the roads' far ends are dead ends: no cycle, so no strong component
  // of all).
  const LaneGraph graph = build_lane_graph(t.map);
  const LaneGraphComponents c = lane_graph_components(graph);
  std::cout << "[ figures  ] T-junction: " << describe_components(c) << "\n";
  EXPECT_EQ(c.weak_sizes.size(), 1u);
  std::vector<LaneGraphNodeId> entries, exits;
  std::vector<int> predecessors(graph.nodes.size(), 0);
  for (const LaneGraphNode& n : graph.nodes)
    for (const LaneGraphNodeId s : n.successors) ++predecessors[size_t(s)];
  for (LaneGraphNodeId n = 0; n < LaneGraphNodeId(graph.nodes.size()); ++n) {
    if (predecessors[size_t(n)] == 0) entries.push_back(n);
    if (graph.nodes[size_t(n)].successors.empty()) exits.push_back(n);
  }
  ASSERT_EQ(entries.size(), 3u);
  ASSERT_EQ(exits.size(), 3u);
  for (const LaneGraphNodeId from : entries) {
    const std::vector<LaneGraphNodeId> reach = reachable_from(graph, from);
    size_t exits_reached = 0;
    for (const LaneGraphNodeId to : exits) exits_reached += std::binary_search(reach.begin(), reach.end(), to);
    EXPECT_EQ(exits_reached, 2u) << "from " << describe_node(graph, from);
  }
  for (const LaneGraphNode& n : graph.nodes) EXPECT_GE(n.length, 3.0) << "a sliver: lanelet " << n.lanelet;
  expect_round_trip(t.map, t.world.description, t.world.world.curb_map(), t.world.materials, t.summary);
}

// The campus (issue 35: its export fell apart into four groups, one per road, and from lanelet 25000
// only 9 of 41 lanelets were reachable): one strongly connected graph, every lanelet reaching every other;
// and the round trip of its world's own lines (no survey).
TEST(Lanelet2Map, CampusIsOneConnectedGraph) {
  Written campus = write_world_map("campus");
  const std::string path = campus.path;
  std::cout << "[ figures  ] campus: " << campus.summary.road_lanelets << " road lanelets ("
            << campus.summary.turn_lanelets << " turning, " << campus.summary.intersection_lanelets
            << " in junctions), " << campus.summary.junctions << " junctions\n";
  EXPECT_EQ(campus.summary.junctions, 5u);
  EXPECT_EQ(campus.summary.short_lanelets, 0u);
  expect_one_strong_component(campus.map, "campus");
  expect_autoware_conventions(path, campus.map, campus.world.description.origin, campus.world.world.pavement());
  std::filesystem::remove(path);
  expect_round_trip(campus.map, campus.world.description, campus.world.world.curb_map(), campus.world.materials,
                    campus.summary);
}

// The routing check on any Lanelet2 map, e.g. an export of `lidarloop map campus --export autoware DIR`:
// LIDARLOOP_ROUTING_CHECK=DIR/lanelet2_map.osm; skipped without it. Prints the graph's components and how
// many lanelets the first lanelet and the worst placed one reach.
TEST(Lanelet2Map, RoutingCheckOfAFile) {
  const char* path = std::getenv("LIDARLOOP_ROUTING_CHECK");
  if (!path) GTEST_SKIP() << "LIDARLOOP_ROUTING_CHECK is not set";
  const Lanelet2Map map = read_lanelet2(path);
  const LaneGraph graph = build_lane_graph(map);
  ASSERT_FALSE(graph.nodes.empty());
  size_t lanelets = 0;
  for (const auto& [id, nodes] : graph.nodes_of) lanelets += !nodes.empty();
  auto reached_lanelets = [&](LaneGraphNodeId from) {
    std::set<Lanelet2Id> ids;
    for (const LaneGraphNodeId n : reachable_from(graph, from)) ids.insert(graph.nodes[size_t(n)].lanelet);
    return ids.size();
  };
  size_t worst = lanelets;
  for (LaneGraphNodeId n = 0; n < LaneGraphNodeId(graph.nodes.size()); ++n)
    worst = std::min(worst, reached_lanelets(n));
  std::cout << "[ figures  ] " << path << ": " << lanelets << " drivable lanelets; "
            << describe_components(lane_graph_components(graph)) << "; from lanelet " << graph.nodes.front().lanelet
            << " " << reached_lanelets(0) << " of " << lanelets << " reachable; the fewest from any: " << worst << "\n";
}

}  // namespace
}  // namespace lidarloop
