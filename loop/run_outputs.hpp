#pragma once
// What `run`, `compare` and `replay` leave in their output folder, written the same way by each:
// metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml and the plots (Fig. 11, 13, 14).
#include <string>
#include <vector>

#include "localizer/hd_map.hpp"
#include "loop/localizer_loop.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {

// The scorer's plain inputs from the loop's records. The truth's stamped poses (the scorer needs no
// speeds or steering):
std::vector<TruthPose> truth_poses(const std::vector<TruthSample>& truth);
// The estimates of an initialised localizer (the ones a recording logs), with the health as words
// and the latency. The yaw is the published one (ros2::published_yaw: through the quaternion of the
// log's Odometry and back), so the run scores what a reader of its log or its TUM export gets.
std::vector<EstimateRecord> estimate_records(const std::vector<LocalizerEstimate>& estimates);

// Scores one method's run with the pure scorer (scoring/scorer.hpp: the thresholds and settle time from
// the scenario, lane keeping along `route`, coverage by the scenario's LiDAR scan period), then
// writes its files into `dir`: metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml,
// errors.png, trajectory.png, and worst_frame.png when `worst` is given (else none); reference.tum too
// when the scenario has a reference (its `reference`, drawn here from the truth and the seed:
// scoring/reference_trajectory.hpp), which the run is scored against beside the truth. `realism`,
// the mount error, the thresholds and the fault events (loop/fault_events.hpp, from the first truth
// stamp) come from `scenario`. `curb_visibility`: the simulator's
// per-scan records (empty when not known). `failure`: what failed the method beyond the thresholds (an
// outside program that did not exit cleanly), or empty. `run`, `compare`, `replay` and `score` all end
// here.
ScoredRun score_and_write(const std::string& dir, const std::string& scenario_name, const Scenario& scenario,
                          const Path& route, const std::vector<TruthPose>& truth, const std::string& method,
                          const std::vector<EstimateRecord>& estimates, const WorstFrame* worst, const HdMap& map,
                          const std::vector<CurbVisibility>& curb_visibility, const std::string& failure = {});

// The same from the loop's records (estimate_records, truth_poses).
ScoredRun score_and_write(const std::string& dir, const std::string& scenario_name, const Scenario& scenario,
                          const Path& route, const std::vector<TruthSample>& truth, const std::string& method,
                          const std::vector<LocalizerEstimate>& estimates, const WorstFrame* worst, const HdMap& map,
                          const std::vector<CurbVisibility>& curb_visibility, const std::string& failure = {});

}  // namespace lidarloop
