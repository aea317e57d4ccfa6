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

LoadedWorld load_world(const std::string& name_or_path) {
  MaterialTable materials = MaterialTable::load(data_dir() + "/assets/materials.yaml");
  const std::string file = world_file(name_or_path);
  const std::string extension = std::filesystem::path(file).extension().string();
  WorldDescription description = extension == ".osm"    ? lanelet2_world_description(file)
                                 : extension == ".xodr" ? opendrive_world_description(file)
                                                        : load_world_description(file);
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
