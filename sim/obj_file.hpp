#pragma once
// Wavefront OBJ in and out: actor assets are read from it, generated worlds are written to it
// (one `usemtl` group per material, so MeshLab / Blender show the materials apart).
#include <string>

#include "sim/materials.hpp"
#include "sim/triangle_mesh.hpp"

namespace lidarloop {

// Reads v / f / usemtl lines (polygons are fanned into triangles); throws InputError with file:line.
TriangleMesh read_obj(const std::string& path, const MaterialTable& materials);
void write_obj(const std::string& path, const TriangleMesh& mesh, const MaterialTable& materials);

}  // namespace lidarloop
