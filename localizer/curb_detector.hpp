#pragma once
// Single-frame curb detection (paper 2.2.1, after its ref. [41]): along each ground-looking laser
// ring, a curb shows up as a short, steep rise of 5-30 cm between two flat stretches (the road and the
// sidewalk). The detected point is the foot of the rise: the road's edge, which is what the curb map
// records.
//
// Beyond the paper: the flat stretches may tilt (a crowned road, a sidewalk's cross-fall, a gutter
// pan), and the rise is read where each of them, carried along its own tilt, meets the step. Read
// between the stretches' medians, as the paper's window statistics do, a slope that runs on through
// both stretches (the 1:10 flares beside a curb ramp, a driveway apron) passes for a curb.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/point_cloud.hpp"
#include "localizer/obstacle_rejection.hpp"

namespace lidarloop {

struct CurbDetectorParams {
  double min_height = 0.05;          // m at the step's ends: lower steps are road texture or noise
  double max_height = 0.30;          // m: higher steps are walls, cars, people
  double step_length = 0.40;         // m along the ring over which the rise must happen
  double flat_length = 0.50;         // m of ring on each side that must be flat
  double max_flat_roughness = 0.02;  // m: RMS height spread allowed on a flat stretch
  double max_range = 25.0;           // m: beyond, ring spacing is too coarse to see a curb
  double max_ground_height = 0.5;    // m above the vehicle's ground plane (z = 0 in the vehicle frame)
};

// `points`: the scan in the vehicle frame (x forward, y left, z up from the ground), in firing order.
// With a `ground` plane (2.1.2), heights are read above it instead (level_to_plane, point by point, so
// the scan is not copied). Returns curb points (x, y) in the vehicle frame.
std::vector<Eigen::Vector2d> detect_curbs(const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<uint16_t>& rings, const CurbDetectorParams& params,
                                          const std::optional<Plane>& ground = std::nullopt);

}  // namespace lidarloop
