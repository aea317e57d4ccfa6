#pragma once
// A localizer that is another program (`--method exec:PROGRAM ARGS`): a ROS 2 node's core, a Python
// prototype, a vendor binary, put in the loop without linking it into lidarloop. The protocol is
// specified in docs/external-localizer.md; in short:
//   - its stdin is an MCAP stream (ROS 2 profile, CDR, unchunked so each message can be read the
//     moment it is written) with the topics and schemas of a lidarloop log but no truth: /tf_static,
//     /vehicle/report, /gps/fix, /gps/heading, /lidar/points, and a Metadata record
//     "lidarloop.external" first (map origin, vehicle, deadlines);
//   - after each scan it writes one line of JSON to stdout, {"scan": N, "x": .., "y": .., "yaw": ..,
//     "stamp_ns": .., "covariance": [9], "lost": bool, "protection": [lateral_m, longitudinal_m]}, or
//     {"scan": N} for "no estimate", and we wait for that line before sending anything more: lockstep,
//     so closed loop works and runs are deterministic. `lost` and `protection` fill the estimate's lost
//     state and protection bounds, so its integrity is scored as a built-in method's;
//   - at the end its stdin gets Data End and the Footer, then end-of-file; it must exit with status 0.
// A program that misses a deadline, writes something else, or exits early ends the run with an
// InputError naming the scan (exit 2); whatever was recorded so far stays a valid log.
#include <map>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "external/child_process.hpp"
#include "localizer/localizer.hpp"
#include "logs/mcap_recorder.hpp"

namespace lidarloop {

inline constexpr const char* kExternalMetadata = "lidarloop.external";
inline constexpr int kExternalProtocolVersion = 1;

// What the program is told before the first message (the values of the "lidarloop.external" metadata).
std::map<std::string, std::string> external_metadata(const HdMap& map, const LocalizerParams& params);

class ExternalLocalizer {
 public:
  // Starts the program (InputError if it cannot) and sends it the stream's start and `metadata`.
  ExternalLocalizer(const LocalizerParams& params, const std::map<std::string, std::string>& metadata);

  void on_can(const CanFrame& frame);
  void on_gps(const GpsFix& fix);
  // Sends the scan, then waits for its answer. total_ms is the wait: the program's latency.
  LocalizerEstimate on_scan(const PointCloud& cloud);
  // Ends the stream and waits for the program to exit; InputError unless it exits with status 0.
  void finish();

 private:
  [[noreturn]] void fail(const std::string& problem, const PointCloud* cloud = nullptr);
  LocalizerEstimate parse_answer(const std::string& line, const PointCloud& cloud);

  LocalizerParams params_;
  std::string label_;
  ChildProcess child_;  // before recorder_: the recorder writes to it from its constructor on
  McapRecorder recorder_;
  int scans_ = 0;
};

}  // namespace lidarloop
