#pragma once
// The reference a run is scored against beside the exact truth (a scenario's `reference`,
// sim/scenario.hpp's ReferenceConfig): the truth plus the error of an RTK-INS reference system, drawn
// once per run from the scenario's seed, at the truth's own samples.
//
// The error has three independent parts, x and y on the map's axes (east, north: a satellite fix's
// error does not turn with the car) and the yaw, each a first-order Gauss-Markov process
//   e_0 = sigma n_0,   e_k = phi_k e_(k-1) + sigma sqrt(1 - phi_k^2) n_k,   phi_k = exp(-(t_k - t_(k-1)) / tau)
// with n_k standard normal: the exact discretisation (sim/gps_model.hpp's, for its receiver), so the
// error's stationary 1 sigma is `sigma` and its autocorrelation exp(-lag / tau) at any sample rate,
// started in its stationary state (the first sample is as far off as any). The reference is the rear
// axle's pose like the truth: a reference system reports its own reference point, and its lever arm is
// surveyed.
//
// Deterministic: draw k of each axis comes from sim/counter_rng.hpp's CounterRng on the reference's
// own stream of the scenario seed, so the reference is a pure function of (truth, config, seed), the
// same in `run`, `compare`, `replay` and `score`, and no other random draw of the run moves when it is
// added or changed.
#include <cstdint>
#include <vector>

#include "scoring/scorer.hpp"
#include "sim/scenario.hpp"

namespace lidarloop {

// One sample's error of the reference: position on the map's axes (m), heading (rad).
struct ReferenceError {
  double x_m = 0, y_m = 0, yaw_rad = 0;
};

// The reference's error at each of `stamps_ns` (sorted, repeats allowed: a repeat has the same error),
// by the model above with `config`'s sigmas and correlation time, whatever its kind. Throws
// std::invalid_argument when the stamps are not sorted, a sigma is negative or the correlation time
// not positive.
std::vector<ReferenceError> reference_errors(const std::vector<int64_t>& stamps_ns, const ReferenceConfig& config,
                                             uint64_t scenario_seed);

// The truth with the reference's error added to each sample (same stamps), the yaw wrapped to
// (-pi, pi]; the truth itself for a reference of kind none.
std::vector<TruthPose> reference_trajectory(const std::vector<TruthPose>& truth, const ReferenceConfig& config,
                                            uint64_t scenario_seed);

}  // namespace lidarloop
