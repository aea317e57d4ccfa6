#pragma once
// The materials table (assets/materials.yaml): LiDAR-relevant surface properties by name.
#include <string>
#include <vector>

#include "sim/triangle_mesh.hpp"

namespace lidarloop {

struct Material {
  std::string name;
  double reflectivity = 0.1;  // diffuse (Lambertian) reflectivity at 905 nm, 0..1
  bool retro = false;         // retro-reflector: returns most light straight back (intensity > 100)
};

class MaterialTable {
 public:
  static MaterialTable load(const std::string& path);

  // Id of a material by name; throws InputError naming `context` when it is unknown.
  MaterialId id(const std::string& name, const std::string& context) const;
  bool contains(const std::string& name) const;
  const Material& operator[](MaterialId id) const { return materials_[id]; }
  size_t size() const { return materials_.size(); }
  const std::string& file() const { return file_; }
  // Materials made while building a world (sim/paint_wear.hpp: a marking's paint with its own
  // reflectivity, under the paint's name), after the file's own: ids size(), size() + 1, ...
  void append(const std::vector<Material>& variants);

 private:
  std::string file_;
  std::vector<Material> materials_;
};

}  // namespace lidarloop
