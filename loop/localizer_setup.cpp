#include "loop/localizer_setup.hpp"

#include <stdexcept>

#include "common/input_error.hpp"
#include "localizer/gicp_matcher.hpp"
#include "loop/kidnap_schedule.hpp"
#include "mapping/map_cache.hpp"
#include "mapping/mapping_drive.hpp"

namespace lidarloop {

LoadedScenario load_scenario_and_world(const std::string& path, std::optional<Realism> realism) {
  Scenario scenario = load_scenario(path, load_vehicle_params(data_dir() + "/assets/vehicle.yaml"), realism);
  LoadedWorld world = load_scenario_world(scenario);
  ResolvedScenario resolved = resolve_scenario(scenario, world.description, world.world);
  // The localizer section is the localizer's to check; do it now so that a typo fails before a run.
  localizer_params_for(scenario);
  return {std::move(scenario), std::move(world), std::move(resolved)};
}

MappingOptions scenario_mapping_options(const Scenario& scenario) {
  MappingOptions options = mapping_options_for(scenario.realism);
  options.paint = scenario.paint;  // the survey saw the same markings, before the drive day's changes
  if (!scenario.text.empty()) {
    const YamlReader y = YamlReader::from_string(scenario.text, scenario.file);
    if (y.root().IsMap() && y.root()["survey"]) read_survey_options(y, y.root()["survey"], options);
  }
  // The street was parked on the survey day too, with other cars.
  if (options.parked_on_survey_day && !scenario.street.parking.stretches.empty())
    options.parked =
        survey_day_parking(scenario.street.parking, load_world_description_of(scenario.world), options.seed);
  return options;
}

HdMap open_scenario_map(const Scenario& scenario, const LoadedWorld& world) {
  const MapLocation map = ensure_map(scenario.world, scenario_mapping_options(scenario), false);
  return open_hd_map(map.dir, world.description.name);
}

LocalizerParams localizer_params_for(const Scenario& s, const std::optional<std::string>& method) {
  LocalizerParams p;
  // The car's datasheet: what a real localizer is configured with.
  const VehicleParams& v = s.ego.vehicle;
  p.vehicle.cornering_stiffness_front = v.cornering_stiffness_front;
  p.vehicle.cornering_stiffness_rear = v.cornering_stiffness_rear;
  p.vehicle.lf = v.lf;
  p.vehicle.lr = v.lr;
  p.vehicle.yaw_inertia = v.yaw_inertia;
  p.vehicle.mass = v.mass;
  p.vehicle.steering_ratio = v.steering_ratio;
  p.vehicle.kinematic_below = v.kinematic_below;
  // The nominal extrinsics (the car's configuration), never the true ones the simulation draws.
  p.lidar_mount = s.lidar.mount();
  p.gps_antenna = s.gps.antenna_xyz;
  p.seed = s.seed;
  if (!s.text.empty()) {
    const YamlReader y = YamlReader::from_string(s.text, s.file);
    if (y.root().IsMap()) read_localizer_params(y, y.root()["localizer"], p);
  }
  if (method) {
    try {
      set_method(p, *method);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--method: ") + e.what());
    }
  }
  if (p.method == LocalizerMethod::gicp && !gicp_available()) throw InputError(kGicpUnavailable);
  check_kidnaps_supported(s, p);
  return p;
}

}  // namespace lidarloop
