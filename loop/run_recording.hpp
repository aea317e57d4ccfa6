#pragma once
// `--record FILE.mcap`: a run's streams as an MCAP log, with what replay needs to redo the run
// exactly: the scenario YAML and the resolved vehicle as attachments, and the seed, method, realism
// profile and map as metadata.
#include <memory>
#include <optional>
#include <string>

#include "localizer/localizer.hpp"
#include "logs/mcap_recorder.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"

namespace lidarloop {

inline constexpr const char* kScenarioAttachment = "scenario.yaml";
inline constexpr const char* kRunMetadata = "lidarloop.run";
// The ego vehicle as the run resolved it (assets/vehicle.yaml, then the scenario's ego.vehicle), in
// assets/vehicle.yaml's format: replay reads it instead of assets/, which may have changed since.
inline constexpr const char* kVehicleAttachment = "vehicle.yaml";

// Every VehicleParams field as assets/vehicle.yaml writes it, each number exact (read_vehicle_params
// reads back the same doubles).
std::string vehicle_yaml(const VehicleParams& vehicle);

// Passes every stream to two sinks (files and a recorder).
class TeeSink : public StreamSink {
 public:
  TeeSink(StreamSink& a, StreamSink* b) : a_(a), b_(b) {}
  void on_truth(const TruthSample& t) override {
    a_.on_truth(t);
    if (b_) b_->on_truth(t);
  }
  void on_can(const CanFrame& f) override {
    a_.on_can(f);
    if (b_) b_->on_can(f);
  }
  void on_gps(const GpsFix& f) override {
    a_.on_gps(f);
    if (b_) b_->on_gps(f);
  }
  void on_rtk(const GpsFix& f) override {
    a_.on_rtk(f);
    if (b_) b_->on_rtk(f);
  }
  void on_scan(const PointCloud& c, const Eigen::Isometry3d& pose) override {
    a_.on_scan(c, pose);
    if (b_) b_->on_scan(c, pose);
  }
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override {
    a_.on_actors(stamp_ns, actors);
    if (b_) b_->on_actors(stamp_ns, actors);
  }
  void on_curb_visibility(const CurbVisibility& v) override {
    a_.on_curb_visibility(v);
    if (b_) b_->on_curb_visibility(v);
  }
  void on_lidar_rotation(const Hdl32eRotation& r, int64_t stamp_ns) override {
    a_.on_lidar_rotation(r, stamp_ns);
    if (b_) b_->on_lidar_rotation(r, stamp_ns);
  }

 private:
  StreamSink& a_;
  StreamSink* b_;
};

// What a log keeps of each scan: the cloud a driver made of it (/lidar/points); that and the
// HDL-32E's raw packets (/velodyne_packets, `--packets`); or the packets alone (`--packets-only`),
// which is the sensor's own data rate: replay and export decode them as a driver does
// (logs/scan_messages.hpp), giving the live run's clouds to the bit.
enum class ScanRecording { points, points_and_packets, packets };

// The simulator's streams into an MCAP log (logs/ knows messages, not the simulator).
class RecordingSink : public StreamSink {
 public:
  RecordingSink(const std::string& path, const Eigen::Isometry3d& lidar_mount, const Eigen::Vector3d& gps_antenna)
      : log_(path, lidar_mount, gps_antenna) {}
  void on_truth(const TruthSample& t) override { log_.write_truth(t); }
  void on_can(const CanFrame& f) override { log_.write_can(f); }
  void on_gps(const GpsFix& f) override { log_.write_gps(f); }
  void on_rtk(const GpsFix& f) override { log_.write_rtk(f); }
  // The sensor pose is not logged separately: /tf (truth) and /tf_static (mount) give it.
  void on_scan(const PointCloud& c, const Eigen::Isometry3d&) override {
    if (scans_ != ScanRecording::packets) log_.write_scan(c);
  }
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override;
  void on_curb_visibility(const CurbVisibility& v) override { log_.write_curb_visibility(v); }
  void on_lidar_rotation(const Hdl32eRotation& r, int64_t stamp_ns) override {
    if (scans_ != ScanRecording::points) log_.write_velodyne_scan(r, stamp_ns);
  }
  void record_scans(ScanRecording scans) { scans_ = scans; }

  McapRecorder& log() { return log_; }

 private:
  McapRecorder log_;
  ScanRecording scans_ = ScanRecording::points;
};

// What /localizer/status says of an estimate (logs/localizer_status.hpp): not initialised is stale,
// lost an error whatever else is wrong, any other health flag a warning.
LocalizerStatus localizer_status(const LocalizerEstimate& estimate);
// An estimate into the log: its status always, its pose once the localizer has one.
void record_estimate(McapRecorder& log, const LocalizerEstimate& estimate);

// Null when `path` is empty. `method` is the localizer's, empty for `simulate`. InputError for
// `scans` other than points without a path.
std::unique_ptr<RecordingSink> start_recording(const std::optional<std::string>& path, const Scenario& scenario,
                                               const std::string& method, ScanRecording scans = ScanRecording::points);

}  // namespace lidarloop
