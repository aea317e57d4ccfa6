#pragma once
// What every command that runs the localizer on a scenario needs: the scenario with its world, the
// HD map of that world (built into the map cache the first time), and the localizer's parameters
// (defaults, then the scenario's `localizer:` overrides, then the car's datasheet and LiDAR mount).
#include <optional>
#include <string>

#include "localizer/hd_map.hpp"
#include "localizer/localizer_params.hpp"
#include "mapping/mapping_drive.hpp"
#include "sim/scenario.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {

struct LoadedScenario {
  Scenario scenario;
  LoadedWorld world;
  ResolvedScenario resolved;
};
// InputError naming the file for anything wrong with the scenario or its world.
// `realism` replaces the scenario's own profile (a command's --realism).
LoadedScenario load_scenario_and_world(const std::string& path, std::optional<Realism> realism = std::nullopt);

// The survey the scenario's map is made by: its realism profile's (mapping_options_for), then the
// scenario's `survey` section.
MappingOptions scenario_mapping_options(const Scenario& scenario);

// Finds or builds the map of the scenario's world (progress on a terminal) and opens it, checking
// that it is the map of `world`.
HdMap open_scenario_map(const Scenario& scenario, const LoadedWorld& world);

// The localizer configuration of a scenario; `method` overrides the scenario's own.
LocalizerParams localizer_params_for(const Scenario& scenario, const std::optional<std::string>& method = {});

}  // namespace lidarloop
