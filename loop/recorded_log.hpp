#pragma once
// What a log recorded by `run --record` or `simulate --record` says about its run, for the commands
// that work on a log instead of simulating (`replay`, `score`): the scenario as it ran (the recorded
// YAML and vehicle, with the run's realism profile and seed from the metadata), the recorded method,
// and what happened (the ground truth, the curb visibility, a scan). Of assets/, only the vehicle of a
// log older than its attachment is read here; the world and its map are too large for a log and are
// found by name (the metadata's map_hash says which map the run had).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/curb_visibility.hpp"
#include "common/hdl32e_driver.hpp"
#include "common/point_cloud.hpp"
#include "common/vehicle_messages.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

struct RecordedRun {
  std::string scenario_text, scenario_name;
  std::map<std::string, std::string> metadata;
  std::string method;  // the recorded localizer method; empty for `simulate`
  Scenario scenario;   // parsed from scenario_text, with the run's realism profile and seed
  // Set for a log recorded before the vehicle was (no kVehicleAttachment): the assets file the vehicle
  // was read from instead, which may differ from the one the run had.
  std::optional<std::string> vehicle_from;
};

// The run's scenario and settings, which the recorder writes before the first chunk: call after the
// reader has handed out its first message (or read the whole file). InputError naming `log` for a
// log without them (not recorded by lidarloop) or with a bad realism profile or seed.
RecordedRun recorded_run(const McapReader& reader, const std::string& log);

// What a log says happened, read in one pass over it.
struct RecordedLog {
  RecordedRun run;
  std::vector<TruthSample> truth;               // /truth/state, in log order
  std::vector<CurbVisibility> curb_visibility;  // /truth/curb_visibility (empty in older logs)
  std::vector<CanFrame> can;                    // /vehicle/report, in log order
};
// InputError naming `log` when it has no ground truth to score against.
RecordedLog read_recorded_log(const std::string& log);

// The calibration of the sensor a log was recorded with, to decode its packets (logs/scan_messages.hpp):
// its scenario's (`lidar:`), else, for a log lidarloop did not record, the stock HDL-32E's, which the
// drivers ship.
Hdl32eCalibration recorded_calibration(const std::string& log);

// The log's last scan stamped at or before `stamp_ns` (the scan an estimate at that time was made
// from, when a localizer stamps its pose at or after the scan's start), else its first scan; nullopt
// for a log without scans. A second pass over the log: scans are large and only one is wanted.
std::optional<PointCloud> recorded_scan_before(const std::string& log, int64_t stamp_ns);

}  // namespace lidarloop
