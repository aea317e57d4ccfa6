#include "sim/materials.hpp"

#include <limits>

#include "common/yaml_reader.hpp"

namespace lidarloop {

MaterialTable MaterialTable::load(const std::string& path) {
  const YamlReader yaml = YamlReader::open(path);
  YamlMap file(yaml, yaml.root(), "the materials file");
  const YAML::Node list = file.required("materials");
  file.done();
  yaml.expect_map(list, "materials");
  MaterialTable table;
  table.file_ = path;
  for (const auto& entry : list) {
    YamlMap material(yaml, entry.second, "material '" + entry.first.Scalar() + "'");
    Material m;
    m.name = entry.first.Scalar();
    m.reflectivity = yaml.number_in(material.required("reflectivity"), "reflectivity", 0.0, 1.0);
    material.boolean("retro", m.retro);
    material["description"];  // for the reader of the file only
    material.done();
    if (table.contains(m.name)) yaml.fail(entry.first, "material '" + m.name + "' is defined twice");
    table.materials_.push_back(m);
  }
  if (table.materials_.empty()) throw InputError(path + ": no materials defined");
  if (table.materials_.size() > std::numeric_limits<MaterialId>::max()) throw InputError(path + ": too many materials");
  return table;
}

void MaterialTable::append(const std::vector<Material>& variants) {
  if (materials_.size() + variants.size() > std::numeric_limits<MaterialId>::max())
    throw InputError(file_ + ": too many materials with the world's paint variants");
  materials_.insert(materials_.end(), variants.begin(), variants.end());
}

bool MaterialTable::contains(const std::string& name) const {
  for (const auto& m : materials_)
    if (m.name == name) return true;
  return false;
}

MaterialId MaterialTable::id(const std::string& name, const std::string& context) const {
  for (size_t i = 0; i < materials_.size(); ++i)
    if (materials_[i].name == name) return static_cast<MaterialId>(i);
  throw InputError(context + ": unknown material '" + name + "' (not in " + file_ + ")");
}

}  // namespace lidarloop
