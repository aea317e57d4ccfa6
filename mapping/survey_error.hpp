#pragma once
// The pose error of the survey car that drives the mapping drive: an RTK-aided INS reports where the car
// is, not where it was, so every scan of the map is placed with the truth pose plus this error.
//
// Position error (east, north) and heading error are each a first-order Gauss-Markov process over the
// distance driven s, propagated with the exact discretisation
//   e <- phi e + sigma sqrt(1 - phi^2) n,  phi = exp(-ds / L),  n ~ N(0, 1)
// so each has stationary standard deviation sigma and autocorrelation exp(-|ds| / L) at any sample
// spacing (the same process as sim/gps_model.hpp, over distance instead of time). The first sample is
// drawn from the stationary law: the INS has been running before the survey starts.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "common/pose2d.hpp"
#include "common/units.hpp"
#include "mapping/slam_map_error.hpp"

namespace lidarloop {

// How the map was made, which sets its error. rtk_ins: a mobile-mapping survey whose every scan is
// placed with an RTK-aided INS (the Gauss-Markov error below, over the distance driven). slam: a
// GNSS-anchored LiDAR-SLAM map (mapping/slam_map_error.hpp: an error field over the ground, the same
// on every pass of a street).
enum class MapProvenance { rtk_ins, slam };
const char* map_provenance_name(MapProvenance provenance);

struct SurveyErrorConfig {
  MapProvenance provenance = MapProvenance::rtk_ins;

  // Applanix POS LV 220 datasheet, RTK column: X, Y position 0.020 m RMS (each horizontal axis).
  double sigma_xy_m = 0.02;
  // Assumption, not on any datasheet: the distance over which the position error decorrelates (RTK
  // multipath and residual atmosphere change as the car moves; of the order of a city block).
  double correlation_length_m = 100.0;
  // Applanix POS LV 220 datasheet, RTK column: true heading 0.050 deg RMS.
  double heading_sigma_rad = 0.05 * kDeg;
  // Assumption, as correlation_length_m: the INS heading error wanders over a similar distance.
  double heading_correlation_length_m = 100.0;
  // No slow drift: with an RTK fix the datasheet's errors are bounded RMS figures; its drift figures
  // are for GNSS outages, which this survey does not have.

  // Distance between samples of the error; linear interpolation in between. Not a physical figure: it
  // must stay far below the correlation lengths (0.5 m against 100 m loses 0.1 % of the variance).
  double sample_spacing_m = 0.5;

  // The map's error when provenance is slam (the fields above, but sample_spacing_m, are then unused).
  SlamMapErrorConfig slam;

  // Every field as text, for the map cache key and the map header. An rtk_ins survey's text has no
  // provenance in it, so maps made before there was a choice keep their cache key.
  std::string describe() const;
};

// The shortest text that reads back as the same double, so any change of a setting changes the text.
std::string exact_number(double v);

// The survey error along a drive of `length_m`, sampled every config.sample_spacing_m.
struct SurveyErrorTrack {
  double spacing_m = 1.0;
  std::vector<Pose2d> samples;  // (east, north, heading) error at s = k * spacing_m

  // The error at distance s driven (linear between samples, clamped to the track's ends). Pure: the
  // LiDAR scanner calls it from several threads.
  Pose2d at(double s) const;
};

// Draws the error of a survey of length_m from `rng` (the caller seeds it). Zero sigmas give an
// all-zero track without drawing differently: the draws per sample stay three, in the order east,
// north, heading.
SurveyErrorTrack simulate_survey_error(const SurveyErrorConfig& config, double length_m, std::mt19937_64& rng);

// Where the survey says the car is: the truth with the error added in the local frame (position error
// east/north, heading error about the car's own position).
Pose2d surveyed_pose(const Pose2d& truth, const Pose2d& error);

// Where the survey puts a point p of the world seen from a car whose true pose is at `truth_xy`: the
// point moves with the car's frame, p + e_xy + (R(e_yaw) - I)(p - truth_xy). Written as a correction
// added to p, so a zero error gives back p bit for bit.
Eigen::Vector2d surveyed_point(const Eigen::Vector2d& p, const Eigen::Vector2d& truth_xy, const Pose2d& error);

}  // namespace lidarloop
