#include "sim/world_assets.hpp"

#include <cstdlib>
#include <filesystem>

#include "common/input_error.hpp"
#include "sim/path.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

std::string data_dir() {
  if (const char* env = std::getenv("LIDARLOOP_DATA"); env && *env) return env;
  return LIDARLOOP_DATA_DIR;
}

std::string actors_dir() { return data_dir() + "/assets/actors"; }

std::string world_file(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  if (name_or_path.find('/') != std::string::npos || fs::path(name_or_path).extension() == ".yaml") {
    if (!fs::is_regular_file(name_or_path)) throw InputError(name_or_path + ": no such world file");
    return name_or_path;
  }
  const std::string path = data_dir() + "/maps/" + name_or_path + "/world.yaml";
  if (!fs::is_regular_file(path)) throw InputError("unknown world '" + name_or_path + "': " + path + " does not exist");
  return path;
}

LoadedWorld load_world(const std::string& name_or_path) {
  MaterialTable materials = MaterialTable::load(data_dir() + "/assets/materials.yaml");
  WorldDescription description = load_world_description(world_file(name_or_path));
  World world = build_world(description, materials, actors_dir());
  return {std::move(materials), std::move(description), std::move(world)};
}

LoadedWorld load_scenario_world(const Scenario& scenario) {
  LoadedWorld w = load_world(scenario.world);
  // The `ideal` profile drives (and maps) the world on ideal ground: flat roads, ideal curbs.
  const bool ideal = scenario.realism == Realism::ideal;
  if (ideal) w.description = on_ideal_ground(std::move(w.description));
  bool changed = false;
  if (!scenario.text.empty()) {
    const YamlReader y = YamlReader::from_string(scenario.text, scenario.file);
    const YAML::Node changes = y.root().IsMap() ? y.root()["world_changes"] : YAML::Node();
    if (changes) w.description = apply_world_changes(std::move(w.description), y, changes), changed = true;
  }
  if (ideal || changed) w.world = build_world(w.description, w.materials, actors_dir());
  return w;
}

Eigen::Isometry3d default_start_pose(const WorldDescription& description, double s) {
  return to_isometry(lane_path(description.roads.front(), Lane::right, false).pose_at(s));
}

}  // namespace lidarloop
