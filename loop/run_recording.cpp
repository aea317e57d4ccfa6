#include "loop/run_recording.hpp"

#include "common/input_error.hpp"
#include "logs/tum_file.hpp"
#include "loop/localizer_setup.hpp"
#include "mapping/map_cache.hpp"
#include "sim/ray_scene.hpp"

namespace lidarloop {
namespace {
std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}
}  // namespace

std::string vehicle_yaml(const VehicleParams& v) {
  const std::pair<const char*, double> numbers[] = {{"cornering_stiffness_front", v.cornering_stiffness_front},
                                                    {"cornering_stiffness_rear", v.cornering_stiffness_rear},
                                                    {"lf", v.lf},
                                                    {"lr", v.lr},
                                                    {"yaw_inertia", v.yaw_inertia},
                                                    {"mass", v.mass},
                                                    {"steering_ratio", v.steering_ratio},
                                                    {"wheel_radius", v.wheel_radius},
                                                    {"track_width", v.track_width},
                                                    {"max_steer", v.max_steer},
                                                    {"max_steer_rate", v.max_steer_rate},
                                                    {"steer_time_constant", v.steer_time_constant},
                                                    {"max_accel", v.max_accel},
                                                    {"max_decel", v.max_decel},
                                                    {"accel_time_constant", v.accel_time_constant},
                                                    {"max_speed", v.max_speed},
                                                    {"kinematic_below", v.kinematic_below}};
  std::string out = "# The ego vehicle of the recorded run: assets/vehicle.yaml with the scenario's ego.vehicle.\n";
  for (const auto& [key, value] : numbers) out += std::string(key) + ": " + round_trip_number(value) + "\n";
  return out + "step_ns: " + std::to_string(v.step_ns) + "\n";
}

void RecordingSink::on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) {
  std::vector<ros2::ActorState> states;
  states.reserve(actors.size());
  for (const auto& a : actors) states.push_back({a.name, actor_type_name(a.type), a.pose});
  log_.write_actors(stamp_ns, states);
}

LocalizerStatus localizer_status(const LocalizerEstimate& e) {
  LocalizerStatus s;
  s.stamp_ns = e.stamp_ns;
  if (e.health & kNotInitialized)
    s.level = ros2::kDiagnosticStale;
  else if (e.lost())
    s.level = ros2::kDiagnosticError;
  else
    s.level = e.ok() ? ros2::kDiagnosticOk : ros2::kDiagnosticWarn;
  s.health = describe_health(e.health);
  s.health_flags = e.health;
  s.lost = e.lost();
  s.protection_lateral_m = e.protection_lateral_m;
  s.protection_longitudinal_m = e.protection_longitudinal_m;
  s.wide_search = e.wide_search;
  if (e.mount_yaw) {
    s.mount_yaw_deg = e.mount_yaw->yaw_rad * kDegPerRad;
    s.mount_yaw_sigma_deg = e.mount_yaw->sigma_rad * kDegPerRad;
  }
  return s;
}

void record_estimate(McapRecorder& log, const LocalizerEstimate& e) {
  const bool has_pose = !(e.health & kNotInitialized);
  log.write_estimate(localizer_status(e), has_pose ? std::optional(e.pose) : std::nullopt, e.covariance);
}

std::unique_ptr<RecordingSink> start_recording(const std::optional<std::string>& path, const Scenario& scenario,
                                               const std::string& method, ScanRecording scans) {
  if (scans != ScanRecording::points && !path)
    throw InputError(std::string(scans == ScanRecording::packets ? "--packets-only" : "--packets") +
                     ": needs --record FILE.mcap");
  if (!path) return nullptr;
  if (path->empty()) throw InputError("--record: needs a file name");
  // The nominal extrinsics, as localizer_params_for gives the localizer (and an exec: program's metadata).
  auto recorder = std::make_unique<RecordingSink>(*path, scenario.lidar.mount(), scenario.gps.antenna_xyz);
  recorder->record_scans(scans);
  McapRecorder& log = recorder->log();
  log.add_attachment(kScenarioAttachment, "application/yaml", scenario.text);
  log.add_attachment(kVehicleAttachment, "application/yaml", vehicle_yaml(scenario.ego.vehicle));
  log.add_metadata(kRunMetadata, {{"scenario", scenario.file},
                                  {"world", scenario.world},
                                  {"seed", std::to_string(scenario.seed)},
                                  {"duration_s", std::to_string(scenario.duration_s)},
                                  {"method", method},
                                  {"loop", scenario.closed_loop ? "closed" : "open"},
                                  {"map_hash", map_hash(scenario.world, scenario_mapping_options(scenario))},
                                  {"realism", realism_name(scenario.realism)},
                                  {"ray_isa", ray_isa()},
                                  {"realism_overrides", join_lines(realism_overrides(scenario))},
                                  {"version", LIDARLOOP_VERSION}});
  return recorder;
}

}  // namespace lidarloop
