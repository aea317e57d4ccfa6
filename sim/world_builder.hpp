#pragma once
// The world generator: turns a WorldDescription into a triangle mesh with a material per triangle,
// and the curb lines that become the curb map.
//
// Surfaces: the carriageway follows the terrain, falls from each road's centreline to its curbs (the
// crown) and is rough as its ISO 8608 class. Along its edge runs the curb band (sim/curb_band.hpp:
// gutter, face, top, cuts); curb tops, ramps, sidewalks and the ground beyond continue from it. Paint
// lies `paint_height` above the pavement.
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "sim/curb_band.hpp"
#include "sim/materials.hpp"
#include "sim/region.hpp"
#include "sim/road_surface.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct World {
  std::string name;
  Geodetic origin;
  TriangleMesh mesh;
  // Lines along the carriageway's edge, split where the curb's kind changes (closed rings repeat their
  // first point), and each one's kind: a profile (vertical, sloped, rolled) or a cut (driveway, ramp,
  // flush).
  std::vector<Polyline2d> curbs;
  std::vector<std::string> curb_kinds;
  region::Paths carriageway;  // area between the curbs
  region::Paths sidewalks;    // carriageway + curbs + sidewalks
  Eigen::AlignedBox2d bounds;
  std::shared_ptr<const RoadSurface> surface;                 // terrain, crown, roughness
  std::shared_ptr<const RaisedGround> curb_band;              // the curbs' cross-sections
  std::function<float(const Eigen::Vector2d&)> raised_level;  // curb top / sidewalk height at a point
  // A world imported from a map: what was built of it and what not (sim/lanelet2_world.hpp); empty for
  // a generated world.
  std::string import_report;
  // The markings' own paint materials (sim/paint_wear.hpp), to be appended to the table the world was
  // built with (MaterialTable::append): its triangles use their ids. Empty for uniform paint.
  std::vector<Material> paint_materials;

  CurbMap curb_map() const { return {origin, name, curbs, curb_kinds}; }
  // What stands on the world: the pavement on the carriageway, the raised ground elsewhere. The
  // function keeps what it needs, so it outlives the World.
  GroundHeight ground() const;
  GroundHeight pavement() const;  // the carriageway's surface, extended everywhere
};

// actors_dir holds the OBJ meshes of parked vehicles (assets/actors). Throws InputError naming the
// world file and the entry for geometry that cannot be built (objects on the carriageway, unknown materials).
World build_world(const WorldDescription& description, const MaterialTable& materials, const std::string& actors_dir);

}  // namespace lidarloop
