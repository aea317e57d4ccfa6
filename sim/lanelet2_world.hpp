#pragma once
// A simulator World from a parsed Lanelet2 map (sim/lanelet2_file.hpp): everything the map says becomes
// geometry, and what does not is counted and named in the build report.
//
//   road, highway, play_street, bus_lane, emergency_lane and (on-road) bicycle_lane lanelets
//                       the carriageway: the union of their polygons (left bound + reversed right bound),
//                       closed a little to remove slivers; surface z from the points' `ele`
//                       (interpolated), a cross-fall where the map has none, ISO 8608 roughness
//   curbstone           a curb face along the way, up to the side away from the carriageway (high:
//                       vertical; low: sloped, mountable); World::curbs gets each way as it is
//   road_border         the pavement's edge with the ground flush beyond it
//   walkway, traffic_island areas
//                       raised behind their curbs, paved (sidewalk)
//   line_thin / line_thick (solid, dashed, solid_solid, dashed_solid, solid_dashed, dashed_dashed)
//                       paint strips of the national standard's width and dash pattern
//   stop_line, zebra_marking, pedestrian_marking, bike_marking
//                       paint (zebra stripes between the two zebra bounds of a lanelet)
//   wall, fence, guard_rail ways, building areas
//                       extruded
//   vegetation areas    grass, trees on a grid, hedges along their edge away from the road
//   parking areas       stalls in rows along the area's long axis, filled with parked cars at an occupancy
//   traffic_light / traffic_sign ways
//                       poles with retro-reflective plates
//   virtual lines       nothing, by design
// Anything else (keepout, rail, zig-zag, symbol lines, exit / keepout areas, crosswalk and walkway
// lanelets, regulatory elements) is not built and is named in Lanelet2BuildReport::not_built.
//
// The standards a default comes from depend on the country (params.country, else the map's `region`
// tag, else Germany: Lanelet2's default traffic rules are German): see lanelet2_standards().
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sim/lane_graph.hpp"
#include "sim/lanelet2_file.hpp"
#include "sim/materials.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

// The dimensions a country's standards give for what a Lanelet2 map leaves unsaid.
struct Lanelet2Standards {
  std::string country;  // "de" or "us" (other countries take Germany's, the Vienna Convention's shapes)
  // Carriageway cross slope from its edge up to the crown. DE: RAS-Q 96 / RASt 06, 2.5 % (Regelquerneigung);
  // US: TxDOT Roadway Design Manual, 2 % recommended (1-4 % allowed).
  double cross_slope = 0.025;
  // The crown lies at most this far in from the edge (one lane; wider pavements have a level plateau
  // between their crowns). DE: RASt 06, 3.50 m lanes on main roads; US: AASHTO Green Book, 12 ft (3.6 m).
  double crown_distance = 3.5;
  // Curb reveals. DE: RASt 06 / DIN 483 Hochbord 0.10-0.12 m (0.12 m), a lowered (low) curb 0.03 m
  // (DIN 18040-3: 3 cm at crossings). US: AASHTO Green Book 4.7, 6 in (0.15 m) barrier curb, 4 in
  // (0.10 m) mountable curb.
  double curb_high = 0.12, curb_low = 0.03;
  // Low curbs are mountable: a sloped face (AASHTO Green Book 4.7 "sloping curbs"; DIN 483 Flachbord /
  // Rundbord), rising over a run equal to its height (sim/curb_band.hpp).
  CurbProfile low_profile = CurbProfile::sloped;
  // Lines. DE: RMS-1 (Richtlinien für die Markierung von Straßen, Teil 1, 1993): Schmalstrich 0.12 m,
  // Breitstrich 0.25 m, Leitlinie innerorts 3 m line / 6 m gap, double lines 0.12 m apart.
  // US: MUTCD (2009) 3A.05 normal line 4-6 in (0.15 m taken), wide line twice that; 3A.06 broken line
  // 10 ft segments, 30 ft gaps; double lines separated by a discernible space (4 in taken).
  double thin_width = 0.12, thick_width = 0.25;
  double dash = 3.0, gap = 6.0;
  double double_spacing = 0.12;  // clear space between the two lines of a double line
  // Stop line. DE: RMS-1 Haltlinie (Zeichen 294), a 0.50 m Breitstrich; US: MUTCD 3B.16, 12-24 in (0.30 m).
  double stop_width = 0.50;
  // Zebra crossing. DE: RMS-1 Fußgängerüberweg (Zeichen 293): 0.50 m stripes, 0.50 m gaps, 4 m long
  // (3 m minimum). US: MUTCD 3B.18 longitudinal bars, 0.6 m (24 in) bars and gaps taken (FHWA high
  // visibility crosswalk practice).
  double zebra_stripe = 0.50, zebra_gap = 0.50, zebra_length = 4.0;
  // Pedestrian crossing at signals (Fußgängerfurt: a dashed Schmalstrich, RMS-1; US: MUTCD 3B.18
  // transverse lines 6-24 in, 6 in taken, shown dashed 0.5 / 0.2 m as the German one).
  double pedestrian_width = 0.12, pedestrian_dash = 0.5, pedestrian_gap = 0.2;
  // Cycle crossing (Radwegfurt: RMS-1 / ERA 2010, a 0.25 m Breitstrich, 0.50 m dashes, 0.20 m gaps;
  // US: MUTCD 3B.08 dotted extension lines, 2 ft segments, 2-6 ft gaps: 4 ft taken, 6 in wide).
  double bike_width = 0.25, bike_dash = 0.5, bike_gap = 0.2;
  // Parking stalls. DE: EAR 05 (Empfehlungen für Anlagen des ruhenden Verkehrs): perpendicular 2.50 m x
  // 5.00 m, parallel 2.00 m x 5.70 m. US: ITE / common municipal codes: 8.5 ft x 18 ft, 8 ft x 22 ft.
  double stall_width = 2.5, stall_depth = 5.0;
  double parallel_width = 2.0, parallel_length = 5.7;
  // A traffic sign's lower edge when the map gives no height. DE: VwV-StVO zu §§ 39-43, 2.00 m over
  // footways; US: MUTCD 2A.18, 7 ft (2.1 m) in business and residential areas.
  double sign_bottom = 2.0;
  double sign_size = 0.6;  // DE: VwV-StVO size 2, a 600 mm round sign; US: MUTCD 2B.03, 24-30 in
};

// The standards of a country ("de", "us"; anything else: Germany's).
Lanelet2Standards lanelet2_standards(const std::string& country);

struct Lanelet2WorldParams {
  std::string country;  // "" : the map's `region` tag, else "de"
  // Overrides of the country's standards (unset: lanelet2_standards(country)).
  std::optional<double> curb_high, curb_low, cross_slope;
  // Paint height, roughness (ISO 8608 class, seed), margin round the map: as the generated worlds.
  WorldGeometryParams geometry;
  // Gaps between neighbouring lanelets narrower than twice this are closed (slivers from bounds that
  // do not quite meet), m.
  double sliver_radius = 0.25;
  uint64_t seed = 1;  // parked vehicles' choice of stalls and headings (std::mt19937_64)
  // Share of parking stalls occupied: Shoup, "The High Cost of Free Parking" (2005): 85 % is the target
  // occupancy at which a curb or lot is full enough yet has a free space on every block.
  double parking_occupancy = 0.85;
  // Extruded heights. Walls: 2.0 m, the height up to which an enclosure may stand on the boundary
  // without a setback (Landesbauordnung Baden-Württemberg § 6 (1)); 0.24 m thick (DIN 4172 brick
  // dimension). Fences: 1.8 m (an assumption: common panel fences are 0.8-2.4 m), 0.05 m thick. Guard
  // rails: EN 1317 W-beam, top at 0.75 m, rail 0.31 m tall, posts every 2 m (German Schutzplanke).
  double wall_height = 2.0, wall_thickness = 0.24;
  double fence_height = 1.8, fence_thickness = 0.05;
  double guard_rail_height = 0.75, guard_rail_beam = 0.31, guard_rail_post_spacing = 2.0;
  // Buildings with no `height` tag: 3 storeys of 3 m plus a parapet (an assumption; DIN 4172 storey
  // heights are 2.75-3.0 m).
  double building_height = 10.0;
  // Vegetation: trees on a grid this far apart (FLL Empfehlungen für Baumpflanzungen: 8-12 m between
  // urban trees), kept this far inside the area's edge; 8 m tall with a 2.5 m crown (an assumption:
  // a young urban lime or plane). Hedges 1.2 m tall, 0.8 m deep, just inside the edge, except within
  // hedge_clearance of the carriageway (a hedge there would hide the curbs the localizer needs).
  double tree_spacing = 10.0, tree_inset = 1.5, tree_height = 8.0, tree_crown_radius = 2.5;
  double hedge_height = 1.2, hedge_depth = 0.8, hedge_inset = 0.2, hedge_clearance = 2.0;
  // Traffic lights with no height in the map: housing bottom 2.4 m above the ground (MUTCD 4D.15: at
  // least 8 ft over a sidewalk), housing 0.9 m tall (three 200 mm lenses, EN 12368).
  double light_bottom = 2.4, light_height = 0.9;
  // The markings' wear (sim/paint_wear.hpp): not a key of the world file; build_world sets it from the
  // world's description (a scenario's `paint`). Unset: uniform paint.
  std::optional<PaintConditions> paint;
};

struct Lanelet2BuildReport {
  std::string country;    // whose standards were used
  int road_lanelets = 0;  // lanelets in the carriageway (road, highway, ... and on-road bicycle lanes)
  int cycle_tracks = 0;   // bicycle lanes behind a curb: paved at the raised level
  int curbstones_high = 0, curbstones_low = 0;
  double curb_length_m = 0;  // of all curbstone ways
  int road_borders = 0;
  std::map<std::string, int> paint_lines;  // "line_thin dashed": ways painted
  int stop_lines = 0, zebra_markings = 0, pedestrian_markings = 0, bike_markings = 0;
  int zebra_stripes = 0;
  int walls = 0, fences = 0, guard_rails = 0, buildings = 0;
  int walkway_areas = 0, traffic_islands = 0;
  int vegetation_areas = 0, trees = 0, hedges = 0;
  int parking_areas = 0, parking_stalls = 0, parked_vehicles = 0;
  int traffic_lights = 0, traffic_signs = 0;
  std::map<std::string, int> not_built;  // "keepout area": 2, "virtual: not drawn": 187
  std::vector<std::string> warnings;     // e.g. a map without curbstones
  std::string cross_fall;                // where the carriageway's cross-fall came from

  std::string summary() const;  // several lines, for the CLI
};

// A world's road network from a Lanelet2 map: the map as read, its routing graph (every route of the
// ego, the traffic and the mapping drive is planned on it), and how to build it.
struct Lanelet2Source {
  std::string file;   // the map, as the world names it (resolved against the world file's folder)
  std::string where;  // the world file's entry, file:line:col, for later errors
  Lanelet2Map map;
  LaneGraph graph;
  Lanelet2WorldParams params;
};

// Reads the map at `file` (sim/lanelet2_file.hpp) and builds its routing graph once.
std::shared_ptr<const Lanelet2Source> load_lanelet2_source(const std::string& file, const std::string& where,
                                                           const Lanelet2WorldParams& params,
                                                           const Lanelet2ReadOptions& read = {});

// Builds the world. actors_dir holds the parked vehicles' meshes (assets/actors). Throws InputError
// (naming the map file) for a map whose carriageway is empty.
World build_lanelet2_world(const Lanelet2Map& map, const Lanelet2WorldParams& params, const MaterialTable& materials,
                           const std::string& actors_dir, Lanelet2BuildReport* report = nullptr);

}  // namespace lidarloop
