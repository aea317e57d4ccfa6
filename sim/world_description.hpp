#pragma once
// A world as its author describes it in maps/<world>/world.yaml: a WGS-84 origin and a road network of
// centrelines in local metres, with curbs, sidewalks, paint, and objects beside the road.
// Loading validates everything that can be checked without building geometry; every error names the
// file, line and column.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/curb_map_file.hpp"
#include "common/geodetic.hpp"
#include "common/yaml_reader.hpp"
#include "sim/paint_wear.hpp"

namespace lidarloop {

enum class MarkingStyle { none, solid, dashed };
enum class RoadSide { left, right, both };  // relative to the centreline's direction
// The curb's cross-section (AASHTO "A Policy on Geometric Design of Highways and Streets", section 4.7:
// vertical or barrier curbs, and sloping curbs that vehicles can mount; rolled curbs are the S-shaped
// mountable kind of residential streets).
enum class CurbProfile { vertical, sloped, rolled };
// Where a curb is cut to the level of the road: a driveway, a curb ramp (ADA Standards 406), or a
// stretch with no curb at all (a bus bay or lay-by, a parking lane with a painted edge only).
enum class CurbCut { driveway, ramp, flush };

struct RoadSpec {
  std::string name;
  std::string where;      // file:line:col of the road's entry, for later errors
  Polyline2d points;      // as written
  Polyline2d centreline;  // after corner smoothing; closed lines repeat their first point
  bool closed = false;    // a loop: the last point joins the first
  double width = 7.0;     // carriageway, curb face to curb face
  int lanes = 2;
  bool one_way = false;
  MarkingStyle marking = MarkingStyle::dashed;  // lane dividers
  bool edge_lines = true;
  double curb_height = 0.15;
  double sidewalk_width = 3.0;
  double smoothing_radius = 0;  // fillet radius for centreline corners
  // The carriageway falls by this much per metre from its centreline to each curb (the crown):
  // TxDOT Roadway Design Manual, 2 % recommended, 1-4 % allowed.
  double cross_slope = 0.02;
  CurbProfile curb_profile = CurbProfile::vertical;
  // Curb reveal varies along a road, mostly because asphalt overlays bury part of it (a 40-50 mm mill
  // and overlay lowers it by that much): the height wanders smoothly within +-this, m.
  double curb_height_variation = 0;
  // Gutter pan in front of the curb (AASHTO Green Book 4.7: 0.3-1.8 m wide at 5-8 % towards the curb);
  // 0 = none, the pavement meets the curb face.
  double gutter_width = 0;
  double gutter_slope = 0.06;
  double driveway_spacing = 0;  // m between driveway cuts along each side; 0 = none
  double driveway_width = 4.0;  // m, at the curb line
  double verge_width = 0;       // m of grass right behind the curb's top (not across cuts); 0 = none
  // km/h: sets the superelevation of its curves (sim/superelevation.hpp); a campus street's 30 km/h
  // asks for none on a 40 m radius.
  double design_speed = 30;
};

struct CrosswalkSpec {
  std::string where, road;
  double at = 0;       // arc length along the road's centreline, m
  double width = 4.0;  // extent along the road, m
};

struct StopLineSpec {
  std::string where, road;
  double at = 0;
  RoadSide side = RoadSide::right;  // which half of the carriageway it spans
};

// A curb cut written in the world file (driveways at regular spacing come from the road's keys;
// ramps at crosswalks are made for every crosswalk).
struct CurbCutSpec {
  std::string where, road;
  RoadSide side = RoadSide::right;
  double at = 0;       // arc length of its centre along the road's centreline, m
  double length = 10;  // along the curb, m
  CurbCut kind = CurbCut::flush;
};

// A hill of the terrain: a raised-cosine bump, so roads across it climb and descend with a grade
// of at most pi/2 * height / radius.
struct Hill {
  Eigen::Vector2d centre{0, 0};
  double radius = 100, height = 0;
};

struct BuildingSpec {
  std::string where;
  Eigen::Vector2d centre{0, 0}, size{10, 10};
  double yaw = 0, height = 10;
  std::string material = "building";
};

// Objects repeated along a road at a fixed spacing, set back from the curb.
struct RowSpec {
  std::string where, road;
  RoadSide side = RoadSide::both;
  double spacing = 30, setback = 0.5, start = 0;
};
struct PoleRow : RowSpec {
  double height = 6.0;
  bool sign = true;  // a retro-reflective sign plate near the top
};
struct TreeRow : RowSpec {
  double height = 6.0, crown_radius = 2.0;
};
// Street furniture close to the curb. Bollards: steel posts, commonly 0.9-1.1 m tall and 0.15-0.2 m
// across (manufacturers' catalogues; an assumption, no standard fixes them). Hydrants: 0.6-0.9 m tall,
// set about 0.6 m (2 ft) behind the curb face (common municipal practice; an assumption). Neither
// stands in front of a curb cut or on its flares: those places of a row stay empty.
struct BollardRow : RowSpec {
  double height = 1.0, diameter = 0.2;
};
struct HydrantRow : RowSpec {
  double height = 0.75, diameter = 0.25;
};
// A hedge or a row of shrubs along a stretch of one side of a road: `setback` behind the curb line to
// its trunks, `depth` deep; above `clearance` its road-facing side leans out from the curb line to
// `overhang` in front of it at the top, so a LiDAR looking down the road sees leaves where the curb
// is. It follows the curb, leaves curb cuts and their flares open and stops at junctions' corners.
struct HedgeSpec {
  std::string where, road;
  RoadSide side = RoadSide::right;
  double at = 0, length = 20;
  double setback = 0.5, depth = 0.8, height = 1.2, overhang = 0.3, clearance = 0.4;
};

struct ParkedVehicleSpec {
  std::string where;
  std::string type = "car";  // a mesh in assets/actors/
  Eigen::Vector2d position{0, 0};
  double yaw = 0;
};

// How today's world differs from the one the map was surveyed in (a scenario's `world_changes`): a
// stretch of a road whose lane paint has worn away (shift 0) or been repainted `shift` metres to the
// left of where it was, and a construction zone closing one side's lanes with cones and barriers.
struct PaintChange {
  std::string where, road;
  double at = 0, length = 20;  // centre (arc length along the centreline) and extent along the road, m
  double shift = 0;
};
// The zone may also have edited the closed side's curb since the survey: taken out (a flush cut over
// the zone, `curb_removed`) and/or a temporary kerb of precast blocks set `curb_shift` metres into the
// carriageway from the old curb line (a kerb extension narrowing the road); both together: the curb moved.
struct ConstructionZone {
  std::string where, road;
  double at = 0, length = 30;
  RoadSide side = RoadSide::right;
  bool curb_removed = false;
  double curb_shift = 0;  // m; 0: no temporary kerb
};

struct WorldGeometryParams {
  double corner_radius = 8.0;    // curb corner radius where roads meet
  double curb_top_width = 0.15;  // width of the curb stone's top face
  double paint_width = 0.15;
  double paint_height = 0.003;  // paint stands this far above the asphalt
  double dash_length = 3.0, dash_gap = 6.0;
  double edge_line_inset = 0.3;  // edge line centre from the curb, or from the gutter's lip
  double stop_line_width = 0.4;
  double crosswalk_stripe = 0.45, crosswalk_gap = 0.6;
  double margin = 30.0;  // ground beyond the outermost object
  // Sidewalks rise away from the curb; ADA Standards 403.3 allow at most 1:48, built to 1.5 % so
  // construction tolerance stays within it.
  double sidewalk_cross_slope = 0.015;
  // A curb ramp or driveway rises back to the sidewalk at most this steeply (ADA 406.1 / 405.2: 1:12),
  // and curbs taper down to a cut over flared sides of at most 1:10 (ADA 406.3).
  double ramp_slope = 1.0 / 12.0;
  double flare_slope = 1.0 / 10.0;
  // Pavement unevenness as an ISO 8608 road class (A very good ... E very poor), between these
  // wavelengths; shorter ones are texture the beam footprint averages away, longer ones are grade.
  char roughness_class = 'B';                                              // or '-' for a perfectly smooth pavement
  double roughness_min_wavelength = 0.5, roughness_max_wavelength = 10.0;  // m
  uint64_t roughness_seed = 1;
  bool crosswalk_ramps = true;  // every crosswalk gets a curb ramp on both sides (ADA 406)
  // Curves are banked at most this much: AASHTO 2011 3.3.3, 4 % for urban streets (ice, slow traffic).
  double max_superelevation = 0.04;
};

struct Lanelet2Source;   // sim/lanelet2_world.hpp
struct OpenDriveSource;  // sim/opendrive_world.hpp

struct WorldDescription {
  std::string name, file;
  Geodetic origin;
  WorldGeometryParams geometry;
  std::vector<RoadSpec> roads;
  std::vector<CrosswalkSpec> crosswalks;
  std::vector<StopLineSpec> stop_lines;
  std::vector<CurbCutSpec> curb_cuts;
  std::vector<Hill> hills;
  std::vector<BuildingSpec> buildings;
  std::vector<PoleRow> poles;
  std::vector<TreeRow> trees;
  std::vector<BollardRow> bollards;
  std::vector<HydrantRow> hydrants;
  std::vector<HedgeSpec> hedges;
  std::vector<ParkedVehicleSpec> parked;
  std::vector<PaintChange> paint_changes;  // a world file has none: see apply_world_changes
  // The markings' wear (sim/paint_wear.hpp) and the day they are seen on; a world file has none
  // (uniform paint): a scenario's `paint` sets it for the drive (load_scenario_world) and the map's
  // survey (load_mapped_world).
  std::optional<PaintConditions> paint;
  std::vector<ConstructionZone> construction;
  // The road network read from a Lanelet2 map instead of `roads` (world.yaml's `lanelet2`, or a map
  // file given as the world): roads, and everything placed along them, are then empty.
  std::shared_ptr<const Lanelet2Source> lanelet2;
  // The same from an OpenDRIVE map (world.yaml's `opendrive`, or a .xodr file given as the world).
  std::shared_ptr<const OpenDriveSource> opendrive;

  const RoadSpec* road(const std::string& name) const;
};

WorldDescription load_world_description(const std::string& path);

// A `side` key: left, right or both (of a road, in its centreline's direction).
RoadSide read_side(const YamlReader& y, const YAML::Node& n);
// A world that is a Lanelet2 map and nothing else (`lidarloop world MAP.osm`), named after the file.
WorldDescription lanelet2_world_description(const std::string& osm_path);
// A world that is an OpenDRIVE map and nothing else (`lidarloop world MAP.xodr`), named after the file.
WorldDescription opendrive_world_description(const std::string& xodr_path);
// Today's world: `surveyed` (the world file, as the map was surveyed) changed by a scenario's
// `world_changes` mapping: parked vehicles gone (their positions) or new, lane paint worn or
// repainted, construction zones. Errors name the scenario's file:line:col.
WorldDescription apply_world_changes(WorldDescription surveyed, const YamlReader& y, const YAML::Node& changes);

// The same world on ideal ground, as this project built every world before its roads had realism:
// level smooth carriageways and sidewalks, no hills, uniform vertical curbs without gutters or cuts.
// For tests that need known, clean geometry; scenarios never use it.
WorldDescription on_ideal_ground(WorldDescription d);
WorldDescription parse_world_description(const std::string& yaml_text, const std::string& name);

}  // namespace lidarloop
