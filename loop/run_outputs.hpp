#pragma once
// What `run`, `compare` and `replay` leave in their output folder, written the same way by each:
// metrics.json, errors.csv, estimate.tum, truth.tum, junit.xml and the plots (Fig. 11, 13, 14).
#include <string>
#include <vector>

#include "localizer/hd_map.hpp"
#include "loop/localizer_loop.hpp"
#include "loop/scorer.hpp"

namespace lidarloop {

// The scorer's plain inputs from the loop's records. The truth's stamped poses (the scorer needs no
// speeds or steering):
std::vector<TruthPose> truth_poses(const std::vector<TruthSample>& truth);
// The estimates of an initialised localizer, with the health as words and the latency:
std::vector<EstimateRecord> estimate_records(const std::vector<LocalizerEstimate>& estimates);

// Scores one method's run with the pure scorer (loop/scorer.hpp: the thresholds and settle time from
// the scenario, lane keeping along `route`), then writes its files into `dir`. `worst` may be null (no
// bird's-eye picture). `curb_visibility`: the simulator's per-scan records (empty when not known).
ScoredRun score_and_write(const std::string& dir, const std::string& scenario_name, const Scenario& scenario,
                          const Path& route, const std::vector<TruthSample>& truth, const std::string& method,
                          const std::vector<LocalizerEstimate>& estimates, const WorstFrame* worst, const HdMap& map,
                          const std::vector<CurbVisibility>& curb_visibility);

}  // namespace lidarloop
