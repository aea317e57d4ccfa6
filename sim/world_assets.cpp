#include "sim/world_assets.hpp"

#include <cstdlib>
#include <filesystem>

#include "common/input_error.hpp"
#include "sim/lane_graph.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/path.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

std::string data_dir() {
  if (const char* env = std::getenv("LIDARLOOP_DATA"); env && *env) return env;
  return LIDARLOOP_DATA_DIR;
}

std::string actors_dir() { return data_dir() + "/assets/actors"; }

bool names_a_world_file(const std::string& name_or_path) {
  const std::string extension = std::filesystem::path(name_or_path).extension().string();
  return name_or_path.find('/') != std::string::npos || extension == ".yaml" || extension == ".osm" ||
         extension == ".xodr";
}

std::string world_file(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  if (names_a_world_file(name_or_path)) {
    if (!fs::is_regular_file(name_or_path)) throw InputError(name_or_path + ": no such world file");
    return name_or_path;
  }
  const std::string path = data_dir() + "/maps/" + name_or_path + "/world.yaml";
  if (!fs::is_regular_file(path)) throw InputError("unknown world '" + name_or_path + "': " + path + " does not exist");
  return path;
}

WorldDescription load_world_description_of(const std::string& name_or_path) {
  const std::string file = world_file(name_or_path);
  const std::string extension = std::filesystem::path(file).extension().string();
  return extension == ".osm"    ? lanelet2_world_description(file)
         : extension == ".xodr" ? opendrive_world_description(file)
                                : load_world_description(file);
}

LoadedWorld build_loaded_world(WorldDescription description) {
  MaterialTable materials = MaterialTable::load(data_dir() + "/assets/materials.yaml");
  World world = build_world(description, materials, actors_dir());
  materials.append(world.paint_materials);
  return {std::move(materials), std::move(description), std::move(world)};
}

LoadedWorld load_world(const std::string& name_or_path) {
  return build_loaded_world(load_world_description_of(name_or_path));
}

LoadedWorld load_scenario_world(const Scenario& scenario) {
  WorldDescription description = load_world_description_of(scenario.world);
  // The `ideal` profile drives (and maps) the world on ideal ground: flat roads, ideal curbs.
  if (scenario.realism == Realism::ideal) description = on_ideal_ground(std::move(description));
  if (!scenario.text.empty()) {
    const YamlReader y = YamlReader::from_string(scenario.text, scenario.file);
    const YAML::Node changes = y.root().IsMap() ? y.root()["world_changes"] : YAML::Node();
    if (changes) description = apply_world_changes(std::move(description), y, changes);
  }
  description.paint = PaintConditions{scenario.paint, PaintDay::drive};  // today's paint, changed since the survey
  return build_loaded_world(std::move(description));
}

Eigen::Isometry3d default_start_pose(const WorldDescription& description, double s) {
  if (description.lanelet2) {  // the longest of the routes the mapping drive takes
    const LaneGraph& graph = description.lanelet2->graph;
    const auto routes = covering_routes(graph);
    if (routes.empty()) throw InputError(description.lanelet2->file + ": the map has no lanelet a car can drive");
    return to_isometry(make_path(route_driven_line(graph, routes.front()), false).pose_at(s));
  }
  if (description.opendrive) {  // as on a Lanelet2 map
    const LaneGraph& graph = description.opendrive->graph.graph;
    const auto routes = covering_routes(graph);
    if (routes.empty()) throw InputError(description.opendrive->file + ": the map has no lane a car can drive");
    return to_isometry(make_path(route_centreline(graph, routes.front()), false).pose_at(s));
  }
  if (description.roads.empty()) throw InputError(description.file + ": the world has no road to start on");
  return to_isometry(lane_path(description.roads.front(), Lane::right, false).pose_at(s));
}

}  // namespace lidarloop
