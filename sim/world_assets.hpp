#pragma once
// Finding and building the worlds and assets: by name under maps/ and assets/, or by path.
#include <string>

#include "sim/materials.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

// The project's data folder (maps/, assets/): $LIDARLOOP_DATA, else the source tree it was built from.
std::string data_dir();
std::string actors_dir();
// A world given by name (maps/<name>/world.yaml) or by a path to its YAML file.
std::string world_file(const std::string& name_or_path);
// Whether a scenario's `world` names a file (a path, a world.yaml or a Lanelet2 map) rather than a world
// under maps/.
bool names_a_world_file(const std::string& name_or_path);

struct LoadedWorld {
  MaterialTable materials;
  WorldDescription description;
  World world;
};
// The description alone (a world YAML file, a Lanelet2 .osm or an OpenDRIVE .xodr), without building
// its mesh: enough to name the world or to change it before it is built.
WorldDescription load_world_description_of(const std::string& name_or_path);
LoadedWorld load_world(const std::string& name_or_path);
// The materials and the world built from `description` (built once: change the description first).
LoadedWorld build_loaded_world(WorldDescription description);

struct Scenario;
// The world a scenario drives in today: its world file (as the map was surveyed) with the scenario's
// `world_changes` applied.
LoadedWorld load_scenario_world(const Scenario& scenario);

// A sensible place to put a car: `s` metres along the first road, in the right-hand lane, heading along it.
Eigen::Isometry3d default_start_pose(const WorldDescription& description, double s = 20.0);

}  // namespace lidarloop
