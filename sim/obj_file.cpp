#include "sim/obj_file.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "common/input_error.hpp"

namespace lidarloop {

TriangleMesh read_obj(const std::string& path, const MaterialTable& materials) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open mesh file");
  TriangleMesh mesh;
  bool have_material = false;
  MaterialId material = 0;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::string where = path + ":" + std::to_string(line_no);
    std::istringstream words(line);
    std::string tag;
    if (!(words >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Eigen::Vector3f v;
      if (!(words >> v.x() >> v.y() >> v.z()) || !v.allFinite()) throw InputError(where + ": bad vertex");
      mesh.vertices.push_back(v);
    } else if (tag == "usemtl") {
      std::string name;
      words >> name;
      material = materials.id(name, where);
      have_material = true;
    } else if (tag == "f") {
      if (!have_material) throw InputError(where + ": face before any usemtl");
      std::vector<uint32_t> corners;
      std::string corner;
      while (words >> corner) {
        long index = 0;
        try {
          index = std::stol(corner.substr(0, corner.find('/')));
        } catch (const std::exception&) {
          throw InputError(where + ": bad face index '" + corner + "'");
        }
        if (index < 0) index += static_cast<long>(mesh.vertices.size()) + 1;
        if (index < 1 || index > static_cast<long>(mesh.vertices.size()))
          throw InputError(where + ": face index " + corner + " refers to no vertex");
        corners.push_back(static_cast<uint32_t>(index - 1));
      }
      if (corners.size() < 3) throw InputError(where + ": face with fewer than 3 vertices");
      for (size_t i = 1; i + 1 < corners.size(); ++i)
        mesh.add_triangle(corners[0], corners[i], corners[i + 1], material);
    } else if (tag == "o" || tag == "g" || tag == "s" || tag == "vn" || tag == "vt" || tag == "mtllib") {
      continue;  // names, smoothing and texture data mean nothing to a LiDAR
    } else {
      throw InputError(where + ": unsupported OBJ statement '" + tag + "'");
    }
  }
  if (mesh.triangles.empty()) throw InputError(path + ": mesh has no faces");
  return mesh;
}

void write_obj(const std::string& path, const TriangleMesh& mesh, const MaterialTable& materials) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write file");
  out << "# lidarloop world mesh: " << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
      << " triangles; x east, y north, z up, metres\n";
  char buf[96];
  for (const auto& v : mesh.vertices) {
    std::snprintf(buf, sizeof buf, "v %.4f %.4f %.4f\n", v.x(), v.y(), v.z());
    out << buf;
  }
  for (MaterialId m = 0; m < materials.size(); ++m) {
    bool started = false;
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      if (mesh.materials[i] != m) continue;
      if (!started) out << "usemtl " << materials[m].name << '\n';
      started = true;
      const auto& t = mesh.triangles[i];
      out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
  }
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace lidarloop
