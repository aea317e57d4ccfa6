#pragma once
// The world generator: turns a WorldDescription into a triangle mesh with a material per triangle,
// and the curb lines that become the curb map.
//
// Surfaces: the carriageway (asphalt) lies at z = 0. Curb faces rise vertically from it along the
// carriageway's boundary to the curb height; curb tops, sidewalks and the ground beyond are at that
// raised level. Where roads with different curb heights meet, the raised level takes the height of
// the nearest road. Paint lies `paint_height` above the asphalt.
#include <string>

#include <Eigen/Geometry>

#include "sim/materials.hpp"
#include "sim/region.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct World {
  std::string name;
  Geodetic origin;
  TriangleMesh mesh;
  std::vector<Polyline2d> curbs;  // closed rings along the carriageway's edge (first point repeated)
  region::Paths carriageway;      // area between the curbs
  region::Paths sidewalks;        // carriageway + curbs + sidewalks
  Eigen::AlignedBox2d bounds;
  std::function<float(const Eigen::Vector2d&)> raised_level;  // sidewalk height at a point

  CurbMap curb_map() const { return {origin, name, curbs}; }
};

// actors_dir holds the OBJ meshes of parked vehicles (assets/actors). Throws InputError naming the
// world file and the entry for geometry that cannot be built (objects on the carriageway, unknown materials).
World build_world(const WorldDescription& description, const MaterialTable& materials, const std::string& actors_dir);

}  // namespace lidarloop
