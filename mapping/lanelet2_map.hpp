#pragma once
// The vector map Autoware plans on: a world's lanes, crosswalks and stop lines and the surveyed curbs as
// a Lanelet2 map in OSM XML, written with pugixml (the XML library sim/lanelet2_file.cpp reads Lanelet2
// maps with, so one library reads and writes). The conventions come from Lanelet2's documentation
// (lanelet2_core/doc/LinestringTagging.md, LaneletAndAreaTagging.md) and Autoware's extension of it
// (autoware_lanelet2_extension/docs/lanelet2_format_extension.md, extra_regulatory_elements.md) and
// vector map requirements (vm-01-01 lanes, vm-03-02 intersections, vm-05-01 crosswalks); each is cited
// where it is used. sim/lanelet2_file.hpp reads it back and sim/lane_graph.hpp routes on it.
//
// What is written:
//   - a <MetaInfo format_version map_version> element, as Autoware's map loader checks;
//   - one lanelet (type=lanelet, subtype=road, speed_limit the road's design speed) per lane of every
//     road, its `left` and `right` members the lane's bounds: the lane markings between lanes
//     (type=line_thin, subtype=dashed|solid as the road's `marking`, type=virtual where it has none)
//     and the carriageway's edges (type=road_border: the curbs themselves are split wherever their kind
//     changes and go round corners, so no one curb runs along a whole lane); every bound has a
//     lane_change tag (yes across dashed and unpainted dividers, no elsewhere);
//   - junctions where centrelines cross or a road ends on another. A road is cut at each junction's
//     mouths (where both its edges are curbed again past the corners), nowhere else (a closed road
//     without junctions half way round), so no sliver is left at a mouth. A road going on through a
//     junction keeps its lanes across it (turn_direction=straight); for every other movement the roads
//     allow (no U-turns) a connecting lanelet joins the end of each lane arriving by one road to the
//     start of each lane leaving by another, its bounds virtual curves, turn_direction straight, left or
//     right. So the routing graph is one piece wherever the roads connect;
//   - every curb line of the surveyed curb map as a way type=curbstone, subtype=high (vertical curbs)
//     or low (sloped, rolled, and cuts: what a vehicle can drive over);
//   - the world's stop lines (type=stop_line), and for every crosswalk a crosswalk lanelet, its polygon
//     and the regulatory element tying them to its stop lines and to the road's lanelets; a direction
//     of travel with no stop line of the world before a crosswalk gets one derived in front of it.
// Every painted line is moved by the survey error as the curbs are (survey_curb_map): the map is the
// survey, not the world. Every node has lat/lon and the tags local_x, local_y (metres in the local
// frame) and ele: the WGS-84 ellipsoidal height map_projector_info.yaml declares, the origin's altitude
// plus the pavement's height there (the point cloud map's z is the same).
//
// Precision: lat/lon are written as the shortest decimals that read back to the same doubles (finer than
// OSM's fixed-point 1e-7 degrees), so a node's lat/lon is its place to well under a millimetre; local_x
// and local_y carry the exact metres.
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
  size_t junctions = 0;
  size_t turn_lanelets = 0;   // connecting lanelets between roads in junctions (among intersection_lanelets)
  size_t short_lanelets = 0;  // lanelets between junctions shorter than 3 m (junctions too close together)
};

// Where the survey put a line of the world (densified and moved by the survey error).
using SurveyedLine = std::function<Polyline2d(const Polyline2d&)>;

// Writes the map of `world` (built as `built`: its carriageway finds the junctions, its pavement gives
// each node's ele with the world origin's altitude) to `path`. `curbs` is the surveyed curb map (the map's
// curbs.geojson) with its kinds; `map_version` goes into MetaInfo. InputError naming the file if it cannot
// be written.
Lanelet2Summary write_lanelet2_map(const std::string& path, const WorldDescription& world, const World& built,
                                   const CurbMap& curbs, const SurveyedLine& surveyed,
                                   const std::string& map_version = "1");

// The Lanelet2 curbstone subtype of a curb kind (CurbMap::kinds).
const char* curbstone_subtype(const std::string& kind);

}  // namespace lidarloop
