#pragma once
// The vector map Autoware plans on: a world's lanes, crosswalks and stop lines and the surveyed curbs as
// a Lanelet2 map in OSM XML, written with libosmium. The conventions come from Lanelet2's documentation
// (lanelet2_core/doc/LinestringTagging.md, LaneletAndAreaTagging.md) and Autoware's extension of it
// (autoware_lanelet2_extension/docs/lanelet2_format_extension.md, extra_regulatory_elements.md) and
// vector map requirements (vm-01-01 lanes, vm-05-01 crosswalks); each is cited where it is used.
//
// What is written:
//   - one lanelet (type=lanelet, subtype=road) per lane of every road, its `left` and `right` members
//     the lane's bounds: the lane markings between lanes (type=line_thin, subtype=dashed|solid as the
//     road's `marking`, type=virtual where it has none) and the carriageway's edges (type=road_border:
//     the curbs themselves are split wherever their kind changes and go round corners, so no one curb
//     runs along a whole lane; type=virtual across a junction's mouth). A road's lanelets are cut where
//     its edges open into another road and close again, and closed roads at least in two, so no
//     lanelet ends where it starts; lanelets in a junction go straight (turn_direction=straight);
//   - every curb line of the surveyed curb map as a way type=curbstone, subtype=high (vertical curbs)
//     or low (sloped, rolled, and cuts: what a vehicle can drive over);
//   - the world's stop lines (type=stop_line), and for every crosswalk a crosswalk lanelet, its polygon
//     and the regulatory element tying them to its stop lines and to the road's lanelets; a direction
//     of travel with no stop line of the world before a crosswalk gets one derived in front of it.
// Every painted line is moved by the survey error as the curbs are (survey_curb_map): the map is the
// survey, not the world. Every node has lat/lon and the tags local_x, local_y (metres in the local
// frame) and ele (the pavement's height there, in the same frame as the point cloud map's z).
//
// Precision: OSM stores lat/lon as fixed-point 1e-7 degrees (libosmium's osmium::Location, as the
// OSM API), about 1.1 cm of latitude, so a node's lat/lon is within 6 mm of its place; local_x and
// local_y carry the exact metres.
#include <cstddef>
#include <functional>
#include <string>

#include "common/curb_map_file.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct Lanelet2Summary {
  size_t nodes = 0, road_lanelets = 0, crosswalks = 0, curbstones = 0;
  size_t intersection_lanelets = 0;  // road lanelets in a junction (an edge open to another road)
  size_t stop_lines = 0;             // the world's
  size_t derived_stop_lines = 0;     // made in front of crosswalks that had none
};

// Where the survey put a line of the world (densified and moved by the survey error).
using SurveyedLine = std::function<Polyline2d(const Polyline2d&)>;

// Writes the map of `world` (built as `built`: its carriageway finds the junctions, its pavement gives
// each node's ele) to `path`. `curbs` is the surveyed curb map (the map's curbs.geojson) with its kinds.
// InputError naming the file if it cannot be written.
Lanelet2Summary write_lanelet2_map(const std::string& path, const WorldDescription& world, const World& built,
                                   const CurbMap& curbs, const SurveyedLine& surveyed);

// The Lanelet2 curbstone subtype of a curb kind (CurbMap::kinds).
const char* curbstone_subtype(const std::string& kind);

}  // namespace lidarloop
