#pragma once
// A Lanelet2 map (`.osm`, OSM XML as Lanelet2, JOSM and Autoware's map tools write it), read into plain
// structs in the world's local frame (x east, y north, z up, metres).
//
// The primitives are Lanelet2's (lanelet2_core/doc/LaneletPrimitives.md): points (OSM nodes), line
// strings (ways, typed by their `type` / `subtype` tags, LinestringTagging.md), lanelets (relations of
// type `lanelet` with a `left` and a `right` bound, LaneletAndAreaTagging.md), areas (relations of type
// `multipolygon`, outer rings of ways) and regulatory elements (relations of type
// `regulatory_element`). Nothing is dropped here: every element is kept with its tags, and what the
// world makes of each is decided by sim/lanelet2_world.hpp.
//
// Coordinates. Either WGS-84 `lat` / `lon` on every node, projected with the world's transverse Mercator
// about `origin` (common/geodetic.hpp), or Autoware's `local_x` / `local_y` (and `ele`) tags, read in
// the frame that `map_projector_info.yaml` beside the file declares (TransverseMercator,
// LocalCartesianUTM, MGRS or Local) and carried into the world's frame through WGS-84 (for Local, taken
// as the world's metres as they are). `ele` is the node's height; nodes without it are at 0.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"

namespace lidarloop {

using Lanelet2Id = int64_t;
using Lanelet2Tags = std::map<std::string, std::string>;

struct Lanelet2LineString {
  Lanelet2Id id = 0;
  std::string type, subtype;  // the `type` and `subtype` tags ("" when absent)
  Lanelet2Tags tags;          // all of the way's tags, type and subtype included
  std::vector<Lanelet2Id> point_ids;
  std::vector<Eigen::Vector3d> points;  // local metres, z from `ele`
  std::string where;                    // "FILE:LINE" of the way, for later errors
};

struct Lanelet2Lanelet {
  Lanelet2Id id = 0;
  std::string subtype;   // road, highway, crosswalk, bicycle_lane, walkway, ... ("" when absent)
  std::string location;  // urban, nonurban ("" when absent)
  Lanelet2Tags tags;
  Lanelet2Id left = 0, right = 0;  // line string ids, as the relation's members give them
  // The bounds' points, oriented the lanelet's way (a bound whose direction is opposite to the
  // other's, as Lanelet2 allows for a shared bound, is reversed here: `left_inverted` says so).
  std::vector<Eigen::Vector3d> left_points, right_points;
  bool left_inverted = false, right_inverted = false;
  std::optional<Lanelet2Id> centerline;  // an explicit `centerline` member, if any
  std::vector<Lanelet2Id> regulatory_elements;
  bool one_way = true;  // `one_way` tag: "no" or "false" for both directions (Lanelet2's default is yes)
  std::optional<double> speed_limit_mps;  // from `speed_limit` (km/h unless it ends in "mph")
  std::string where;
};

// A multipolygon relation (area): its outer rings closed, inner rings as holes.
struct Lanelet2Area {
  Lanelet2Id id = 0;
  std::string subtype;  // walkway, traffic_island, parking, vegetation, building, keepout, ...
  Lanelet2Tags tags;
  std::vector<std::vector<Eigen::Vector3d>> outer, inner;  // rings, first point not repeated
  std::vector<Lanelet2Id> outer_ways, inner_ways;
  std::string where;
};

struct Lanelet2Regulatory {
  Lanelet2Id id = 0;
  std::string subtype;  // traffic_light, traffic_sign, right_of_way, speed_limit, ...
  Lanelet2Tags tags;
  // Members by role (refers, ref_line, yield, right_of_way, cancels, light_bulbs, ...), as ids.
  std::map<std::string, std::vector<Lanelet2Id>> members;
  std::string where;
};

// How the node coordinates were read.
enum class Lanelet2Coordinates { wgs84, transverse_mercator, local_cartesian_utm, mgrs, local };

struct Lanelet2Map {
  std::string file;
  Geodetic origin;  // of the local frame the points are in
  Lanelet2Coordinates coordinates = Lanelet2Coordinates::wgs84;
  std::string country;  // the `region` tag most lanelets carry (e.g. "de"), lower case; "" when absent
  std::map<Lanelet2Id, Lanelet2LineString> lines;
  std::vector<Lanelet2Lanelet> lanelets;
  std::vector<Lanelet2Area> areas;
  std::vector<Lanelet2Regulatory> regulatory;
  // Elements read but of no kind above (a relation of another type, a way no relation or type tag
  // makes anything of is NOT counted here: free ways are in `lines`), by what they are, for the
  // report of what was not built.
  std::map<std::string, int> other_relations;
  std::vector<std::string> warnings;  // things that were read but look wrong, one line each

  const Lanelet2LineString* line(Lanelet2Id id) const;
};

struct Lanelet2ReadOptions {
  // The local frame's origin. Unset: the WGS-84 map's centre (the middle of its nodes' bounding box),
  // or for local_x / local_y maps the projector's own origin.
  std::optional<Geodetic> origin;
  // Points farther than this from the origin are taken for a broken file (a node at 0, 0 in a map of
  // Karlsruhe): HD maps of one operating area span a few tens of kilometres.
  double max_extent_m = 50'000;
};

// Reads `path`. Throws InputError "FILE:LINE: what" (or "FILE: what") on malformed XML, a member or
// node reference to a missing element, a lanelet without a left or right bound or whose bounds cross or
// run opposite ways, a map without lanelets, points farther apart than max_extent_m, a line string of
// one point, an unreadable or unknown map_projector_info.yaml.
Lanelet2Map read_lanelet2(const std::string& path, const Lanelet2ReadOptions& options = {});
// The same from text in memory (no projector file: lat / lon, or local_x / local_y as Local).
Lanelet2Map parse_lanelet2(const std::string& xml, const std::string& name, const Lanelet2ReadOptions& options = {});

}  // namespace lidarloop
