#pragma once
// How much of the curb the traffic hides from the LiDAR in a scan, measured in the true scene: the
// curb lines are sampled at a fixed spacing, and a ray is cast from the LiDAR to each sample within
// the range the localizer reads curbs in. A sample is visible when nothing stops the ray, hidden when
// an actor stops it and the static world alone would not, and left out when the static world stops
// it (a building, the terrain, the curb's own corner): that is hidden in every run, traffic or not.
//
// Each ray meets the actors where they are at its `time` (RayScene's 0..1 over the scan's keyframes);
// the simulator asks at 0, the scan's first firing, where it also reports the sensor pose and actors.
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "common/curb_map_file.hpp"
#include "common/curb_visibility.hpp"
#include "sim/ray_scene.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct CurbVisibilityConfig {
  // Horizontal range from the LiDAR: the localizer's curb detector reads curbs from 1 m (its
  // kMinRange, about the sensor's own minimum range: localizer/curb_detector.cpp) to 25 m
  // (CurbDetectorParams::max_range in localizer/curb_detector.hpp: beyond, the rings are too far apart
  // to show a curb). A curb outside that is not the localizer's loss, hidden or not. (The detector
  // measures from the rear axle, 1.2 m behind the LiDAR; measured from the LiDAR here, the disc is as
  // large, a little further ahead.)
  double min_range_m = 1.0, max_range_m = 25.0;
  // Along each curb line. The detector needs a rise within 0.40 m of ring (CurbDetectorParams::
  // step_length), so every stretch that could give a detection holds a sample; two curbs of a straight
  // road within 25 m are then ~400 rays, under 1 % of a scan's ~70k.
  double spacing_m = 0.25;
  // Rays stop this short of their sample, so the curb's own surfaces at the sample (float mesh) are not
  // in the way; well under the gap a vehicle leaves to the curb, so an actor beside it still counts.
  double stop_short_m = 0.05;
};

// Points `spacing` apart along each line (from its first point; its last, the next line's first or
// a ring's repeated start, is left to that), raised to `top_height` there.
std::vector<Eigen::Vector3f> curb_top_samples(const std::vector<Polyline2d>& lines,
                                              const std::function<float(const Eigen::Vector2d&)>& top_height,
                                              double spacing);
// The world's curbs (World::curbs) at the height of their tops (World::raised_level: the curb top at
// the curb line): for a vertical face, its top edge; for a sloped or rolled one, the point at the
// top's height above the face's foot, in front of the face. Cuts (driveways, ramps, flush stretches)
// are left out: they have no rise for the detector to find, so there is nothing there to hide.
std::vector<Eigen::Vector3f> curb_top_samples(const World& world, double spacing);

// Casts one ray from `origin` to each of `samples` within range (see the config); the record's stamp
// is left 0 for the caller.
CurbVisibility curb_visibility(const RayScene& scene, const std::vector<Eigen::Vector3f>& samples,
                               const Eigen::Vector3f& origin, float time, const CurbVisibilityConfig& config);

}  // namespace lidarloop
