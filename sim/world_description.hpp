#pragma once
// A world as its author describes it in maps/<world>/world.yaml: a WGS-84 origin and a road network of
// centrelines in local metres, with curbs, sidewalks, paint, and objects beside the road.
// Loading validates everything that can be checked without building geometry; every error names the
// file, line and column.
#include <string>
#include <vector>

#include "common/curb_map_file.hpp"
#include "common/geodetic.hpp"

namespace lidarloop {

enum class MarkingStyle { none, solid, dashed };
enum class RoadSide { left, right, both };  // relative to the centreline's direction

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

struct ParkedVehicleSpec {
  std::string where;
  std::string type = "car";  // a mesh in assets/actors/
  Eigen::Vector2d position{0, 0};
  double yaw = 0;
};

struct WorldGeometryParams {
  double corner_radius = 8.0;    // curb corner radius where roads meet
  double curb_top_width = 0.15;  // width of the curb stone's top face
  double paint_width = 0.15;
  double paint_height = 0.003;  // paint stands this far above the asphalt
  double dash_length = 3.0, dash_gap = 6.0;
  double edge_line_inset = 0.3;  // edge line centre from the curb
  double stop_line_width = 0.4;
  double crosswalk_stripe = 0.45, crosswalk_gap = 0.6;
  double margin = 30.0;  // ground beyond the outermost object
};

struct WorldDescription {
  std::string name, file;
  Geodetic origin;
  WorldGeometryParams geometry;
  std::vector<RoadSpec> roads;
  std::vector<CrosswalkSpec> crosswalks;
  std::vector<StopLineSpec> stop_lines;
  std::vector<BuildingSpec> buildings;
  std::vector<PoleRow> poles;
  std::vector<TreeRow> trees;
  std::vector<ParkedVehicleSpec> parked;

  const RoadSpec* road(const std::string& name) const;
};

WorldDescription load_world_description(const std::string& path);
WorldDescription parse_world_description(const std::string& yaml_text, const std::string& name);

}  // namespace lidarloop
