#pragma once
// The simulator and the localizer in one loop: every CAN frame, GPS fix and scan the simulation emits
// goes, in time order, to one or more localizers (one per method: `compare` feeds them all the same
// stream), and each scan's estimate is kept with the ground truth for scoring. In closed loop the
// first method's estimate is what the controller steers on, once its latency has passed.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "localizer/localizer.hpp"
#include "sim/simulation.hpp"

namespace lidarloop {

// The frame with the largest position error of a method, kept for the bird's-eye picture (Fig. 14).
struct WorstFrame {
  double error_m = -1;
  PointCloud cloud;
  Eigen::Isometry3d sensor_pose = Eigen::Isometry3d::Identity();  // true LiDAR pose at the scan's stamp
  ScanFeatures features;
  Pose2d truth, estimate;
};

struct MethodTrace {
  std::string method;
  std::vector<LocalizerEstimate> estimates;
  WorstFrame worst;  // of the frames the scorer rates (not settling or recovering)
  // An outside program that failed after its last answer (did not exit, exited non-zero): the
  // estimates are kept, and the run is to be reported failed with this.
  std::string failure;
};

struct LoopResult {
  std::vector<TruthSample> truth;
  std::vector<CurbVisibility> curb_visibility;  // one per scan, as the simulator measured it
  std::vector<MethodTrace> methods;
  double wall_s = 0;            // whole loop
  double localizer_wall_s = 0;  // inside the localizers
  size_t scans = 0;
  // Closed loop: per estimate the controller was given, ms from its scan's completion to the controller.
  std::vector<double> controller_delays_ms;
};

// The latency model a closed loop uses for `params` (LatencyParams): `automatic` resolved, to the
// measured latency for an exec: program and to one scan period for a built-in method.
LatencyParams controller_latency(const LocalizerParams& params);

// Runs `sim` to its end. `also`: another sink that sees every stream too (a recorder), or null.
// `progress` is called with the fraction done. The localizers run on a thread beside the simulation.
// Closed loop: the controller steers on the first method's newest estimate it has been given (when:
// the first method's controller_latency) carried forward to the present by CAN odometry, once the
// localizer is initialised.
// `on_estimate` sees the first method's every estimate as it is made (a recorder).
LoopResult run_localizer_loop(Simulation& sim, HdMap& map, const std::vector<LocalizerParams>& methods,
                              bool closed_loop, StreamSink* also = nullptr,
                              const std::function<void(double)>& progress = {},
                              const std::function<void(const LocalizerEstimate&)>& on_estimate = {});

}  // namespace lidarloop
