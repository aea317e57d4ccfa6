#include "loop/recorded_log.hpp"

#include "common/input_error.hpp"
#include "logs/log_topics.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/scan_messages.hpp"
#include "loop/run_recording.hpp"
#include "sim/vehicle_model.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {

namespace topics = log_topics;

RecordedRun recorded_run(const McapReader& reader, const std::string& log) {
  RecordedRun run;
  std::optional<std::string> vehicle_text;
  for (const auto& a : reader.attachments()) {
    if (a.name == kScenarioAttachment) run.scenario_text.assign(a.data.begin(), a.data.end());
    if (a.name == kVehicleAttachment) vehicle_text.emplace(a.data.begin(), a.data.end());
  }
  for (const auto& m : reader.metadata())
    if (m.name == kRunMetadata) run.metadata.insert(m.metadata.begin(), m.metadata.end());
  if (run.scenario_text.empty() || run.metadata.empty())
    throw InputError(log + ": no " + kScenarioAttachment + " attachment or " + kRunMetadata +
                     " metadata: not a log recorded by lidarloop run or simulate");
  run.scenario_name = run.metadata.count("scenario") ? run.metadata.at("scenario") : log;
  run.method = run.metadata.count("method") ? run.metadata.at("method") : "";

  // The profile the run had (a --realism on its command line is not in the scenario's text).
  std::optional<Realism> realism;
  if (run.metadata.count("realism")) {
    realism = parse_realism(run.metadata.at("realism"));
    if (!realism) throw InputError(log + ": metadata " + kRunMetadata + " has an unknown realism profile");
  }
  // The vehicle the run had, read as strictly as assets/vehicle.yaml; the scenario's ego.vehicle then
  // sets the same values again.
  VehicleParams vehicle;
  if (vehicle_text) {
    const YamlReader y = YamlReader::from_string(*vehicle_text, log + ": " + kVehicleAttachment);
    if (!y.root().IsNull()) read_vehicle_params(y, y.root(), vehicle);
  } else {
    run.vehicle_from = data_dir() + "/assets/vehicle.yaml";
    vehicle = load_vehicle_params(*run.vehicle_from);
  }
  run.scenario = parse_scenario(run.scenario_text, run.scenario_name, vehicle, realism);
  // A world named as a file is relative to the scenario's folder (load_scenario); the run recorded the
  // path it resolved to, which the scenario's text alone cannot give.
  if (names_a_world_file(run.scenario.world) && run.metadata.count("world"))
    run.scenario.world = run.metadata.at("world");
  try {
    run.scenario.seed = std::stoull(run.metadata.at("seed"));
  } catch (const std::exception&) {
    throw InputError(log + ": metadata " + kRunMetadata + " has no valid seed");
  }
  return run;
}

RecordedLog read_recorded_log(const std::string& log) {
  McapReader reader(log);
  RecordedLog out;
  for (McapMessage message; reader.next(message);) {
    const std::string& topic = message.channel->topic;
    const std::string context = log + " " + topic;
    if (topic == topics::truth_state)
      out.truth.push_back(ros2::decode_truth_state(message.data, context));
    else if (topic == topics::truth_curb_visibility)
      out.curb_visibility.push_back(ros2::decode_curb_visibility(message.data, context));
    else if (topic == topics::vehicle_report)
      out.can.push_back(ros2::decode_vehicle_report(message.data, context));
  }
  out.run = recorded_run(reader, log);
  if (out.truth.empty())
    throw InputError(log + ": no " + std::string(topics::truth_state) + " messages to score against");
  return out;
}

Hdl32eCalibration recorded_calibration(const std::string& log) {
  McapReader reader(log);
  McapMessage first;
  reader.next(first);  // the scenario is written before the first message
  for (const auto& a : reader.attachments())
    if (a.name == kScenarioAttachment) return recorded_run(reader, log).scenario.lidar.calibration();
  return Hdl32eConfig{}.calibration();
}

std::optional<PointCloud> recorded_scan_before(const std::string& log, int64_t stamp_ns) {
  const Hdl32eCalibration calibration = recorded_calibration(log);
  McapReader reader(log);
  std::optional<PointCloud> found;
  for (McapMessage message; reader.next(message);) {
    std::optional<PointCloud> cloud = scan_message(reader, message, calibration);
    if (!cloud) continue;
    if (found && cloud->stamp_ns > stamp_ns) break;  // the first scan, or the latest at or before
    found = std::move(cloud);
  }
  return found;
}

}  // namespace lidarloop
