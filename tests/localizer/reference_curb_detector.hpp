#pragma once
// The oracle for the curb detector: the plain version of the paper's single-frame curb detection
// (2.2.1, after its ref. [41]), as it stood before commit 0235f81 made localizer/curb_detector.cpp
// 2.2x faster. It is kept here, readable and unoptimised, so that tests can demand that the fast
// detector finds exactly its curbs (same points, same order, same bits), and so that the next
// optimisation cannot change the curbs unnoticed. It is documentation too: read it to learn what the
// fast detector computes.
//
// It reads the same CurbDetectorParams as the fast detector. Do not speed it up: if the detector's
// behaviour is meant to change, change both, here first.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "localizer/curb_detector.hpp"

namespace lidarloop::test {

// What lidarloop::detect_curbs must return for the same input: curb points (x, y) in the vehicle
// frame, ring after ring (0 to 63), each ring in firing order.
std::vector<Eigen::Vector2d> reference_detect_curbs(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<uint16_t>& rings,
                                                    const CurbDetectorParams& params);

// Empty when `fast` holds the same curbs as `reference` in the same order, every coordinate with the
// same bits (so 0.0 and -0.0 differ); else what differs, for a test's failure message. The order
// counts although the detector's interface does not promise one: the localizer's beam model keeps
// curbs in index order and breaks ties by it, so a reordering changes what the localizer estimates.
std::string curb_difference(const std::vector<Eigen::Vector2d>& fast, const std::vector<Eigen::Vector2d>& reference);

}  // namespace lidarloop::test
