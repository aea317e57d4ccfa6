#pragma once
// A simulator World from an OpenDRIVE map (sim/opendrive_file.hpp): each lane a surface strip at its
// own height, curbs wherever the height steps up from the carriageway, road marks and crosswalks
// painted, parked cars, and what is not built counted and named in the build report.
//
//   driving, parking, biking, shoulder, border, restricted, median, bus, taxi, HOV, entry, exit, ramps,
//   stop, roadWorks, slipLane, bidirectional lanes
//                       the carriageway: the union of the lanes' strips (sampled along s, slivers closed),
//                       its height each lane's own (elevation, superelevation and lane height together),
//                       ISO 8608 roughness as every world; a lane of these types with a height of its
//                       own above curb_threshold is raised instead (a raised median, a border island)
//   sidewalk, walking, curb lanes
//                       raised: at their own `height`, or sidewalk_height above the road where the map
//                       gives none (CARLA's towns do not)
//   roadMark type="curb" the lanes outside it raised (as a sidewalk without height) where the map has
//                       no height for them, so the curb stands where the mark says
//   the carriageway's edge
//                       a vertical curb face wherever the ground beside it is higher by more than
//                       curb_threshold (and at most max_curb): between a road lane and a sidewalk, and at
//                       a junction's corners; each such run of the edge is a curb line of the world
//   ground beside the roads
//                       continues from the outer edges of the roads' outermost lanes (Shepard blending):
//                       a town's sidewalk level behind its sidewalks, the road's level beside a rural road
//   roadMark solid, broken, solid solid, solid broken, broken solid, broken broken, botts dots, and any
//   mark's explicit <type><line length space tOffset sOffset width>
//                       paint along the lane's outer edge (the centre lane's: the offset reference line)
//   crosswalk objects   stripes parallel to the road across the object's outline (or its length x width)
//   parking lanes, parkingSpace objects
//                       parked cars at parking_occupancy, parallel stalls along parking lanes
//   pole, building objects
//                       a pole; a building extruded from its outline or box
// Not built, and named in the report: lanes of type none (and rail, tram, unknown types), road marks on
// junctions' connecting roads (they would cross one another: see paint_junctions), marks of type grass,
// edge and custom without lines, other objects, signals.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim/materials.hpp"
#include "sim/opendrive_file.hpp"
#include "sim/opendrive_lane_graph.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct OdrWorldParams {
  // The markings' wear (sim/paint_wear.hpp): not a key of the world file; build_world sets it from the
  // world's description (a scenario's `paint`). Unset: uniform paint.
  std::optional<PaintConditions> paint;
  // Paint height, roughness (ISO 8608 class, seed), margin round the map: as the generated worlds.
  WorldGeometryParams geometry;
  // A sidewalk (or curb) lane without a `height`, and a lane outside a curb mark: raised this much above
  // the road. 0.12 m: the German Hochbord reveal (RASt 06 / DIN 483: 0.10-0.12 m); the US barrier curb
  // is 6 in, 0.15 m (AASHTO Green Book 4.7), which `sidewalk_height: 0.15` gives.
  double sidewalk_height = 0.12;
  // A step in the ground at the carriageway's edge above this is a curb (a face and a curb line); at
  // most max_curb: higher steps are walls and embankments, not curbs. 2 cm: below it a LiDAR's 2 cm
  // range noise hides the step (HDL-32E datasheet); 0.5 m: twice the tallest curbs, those of bus
  // stops (Kasseler Sonderbord, up to 0.24 m).
  double curb_threshold = 0.02, max_curb = 0.5;
  // Lanes are sampled along s every `step` metres: a 0.5 m chord on a 10 m radius strays 3 mm from
  // the arc.
  double step = 0.5;
  // Gaps narrower than twice this between strips that do not quite meet (roads joining at a junction's
  // edge) are closed, m.
  double sliver_radius = 0.05;
  // A junction's connecting roads leave gaps between their turns narrower than twice this: closed, as
  // pavement (and any hole among them filled), m.
  double junction_closing = 1.0;
  // Sidewalks end where their roads meet a junction: gaps between them narrower than twice this (the
  // corners) are closed, as sidewalk, m.
  double sidewalk_closing = 2.5;
  // Road-mark widths when the mark has none: RMS-1 (Richtlinien für die Markierung von Straßen):
  // Schmalstrich 0.12 m (weight standard), Breitstrich 0.25 m (bold); broken lines 3 m with 6 m gaps
  // (Leitlinie innerorts); double lines 0.12 m apart.
  double mark_standard = 0.12, mark_bold = 0.25, dash = 3.0, gap = 6.0, double_spacing = 0.12;
  // Botts' dots: round raised pavement markers about 4 in (0.10 m) across, a few feet apart in
  // California's lines (Caltrans Standard Plans A20A); 1.2 m (4 ft) taken, an assumption; drawn as paint.
  double botts_size = 0.10, botts_spacing = 1.2;
  // Crosswalk stripes: RMS-1 Zeichen 293, 0.50 m stripes with 0.50 m gaps, parallel to the traffic.
  double crosswalk_stripe = 0.5, crosswalk_gap = 0.5;
  // Paint on junctions' connecting roads: off, since their lanes overlap and the marks of every turn
  // would cross the junction (CARLA's and esmini's renderings leave junctions unpainted too).
  bool paint_junctions = false;
  // Parked cars. Occupancy: Shoup, "The High Cost of Free Parking" (2005), 85 %. Parallel stalls along
  // parking lanes: EAR 05 (Empfehlungen für Anlagen des ruhenden Verkehrs), 5.70 m long, lanes at least
  // 2.00 m wide.
  double parking_occupancy = 0.85;
  double stall_length = 5.7, stall_min_width = 2.0;
  uint64_t seed = 1;  // which stalls are taken and which way their cars face (std::mt19937_64)
  // Objects without sizes: a pole 0.08 m in radius and 4 m tall (an assumption: a sign post; lamp posts
  // are 4-10 m), a building 10 m tall (three 3 m storeys and a parapet, DIN 4172 storey heights).
  double pole_radius = 0.08, pole_height = 4.0, building_height = 10.0;
};

struct OdrBuildReport {
  int roads = 0, junction_roads = 0, junctions = 0;
  double road_length_m = 0;
  std::map<std::string, int> lanes;  // "driving": lane strips built (per lane section), by type
  int raised_by_default = 0;         // sidewalk lanes without height, raised by sidewalk_height
  int raised_by_curb_mark = 0;       // lanes raised because a curb mark is on their inner edge
  int curb_marks = 0;                // roadMark type="curb" records
  int curb_lines = 0;
  double curb_length_m = 0;
  std::map<std::string, int> paint;  // "broken white": marks painted
  int crosswalks = 0, crosswalk_stripes = 0;
  int parking_stalls = 0, parked_vehicles = 0;
  int poles = 0, buildings = 0;
  std::map<std::string, int> not_built;
  std::vector<std::string> warnings;

  std::string summary() const;  // several lines, for the CLI
};

// A world's road network from an OpenDRIVE map: the map as read, its routing graph (every route of the
// ego, the traffic and the mapping drive is planned on it), and how to build it.
struct OpenDriveSource {
  std::string file;   // the map, as the world names it
  std::string where;  // the world file's entry, file:line:col, for later errors
  OdrMap map;
  OdrLaneGraph graph;
  OdrWorldParams params;
};

// Reads the map at `file` (sim/opendrive_file.hpp) and builds its routing graph once.
std::shared_ptr<const OpenDriveSource> load_opendrive_source(const std::string& file, const std::string& where,
                                                             const OdrWorldParams& params,
                                                             const OdrReadOptions& read = {});

// Builds the world. actors_dir holds the parked vehicles' meshes. Throws InputError (naming the map)
// for a map with no lane to drive on.
World build_opendrive_world(const OdrMap& map, const OdrWorldParams& params, const MaterialTable& materials,
                            const std::string& actors_dir, OdrBuildReport* report = nullptr);

}  // namespace lidarloop
