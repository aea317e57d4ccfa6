#pragma once
// The error of an HD map made the way research fleets make theirs: a LiDAR-SLAM pose graph whose scans
// are registered to one another, closed where the drive comes back, and pulled onto GNSS fixes
// ("anchors") along the way. Such a map is locally consistent (its relative error over tens of metres is
// a few centimetres) and globally only as good as its anchors (its absolute error is of the order
// HD-map vendors quote, 10-20 cm).
//
// Model: the map's planar error is a function of place, e(p) = (east, north), not of the distance
// driven: loop closures make every pass of a street agree, so two lanes of one road carry the same
// error where they run side by side. Each axis is an independent, stationary Gaussian random field
// with Gaussian covariance
//   C(r) = sigma^2 exp(-r^2 / (2 l^2)),  sigma = absolute_sigma_m / sqrt(2) per axis,
// smooth because the optimiser spreads each anchor's correction along the graph rather than jumping.
// Its horizontal relative error over a distance d is
//   E |e(p + d) - e(p)|^2 = 2 absolute_sigma_m^2 (1 - exp(-d^2 / (2 l^2))),
// from which l is set so that it is relative_sigma_m at d = relative_over_m. Over short distances it
// grows in proportion to d, as SLAM drift does (percent of distance travelled), and it saturates at
// sqrt(2) absolute_sigma_m over distances much longer than l, where the anchors hold it.
//
// Drawn as a sum of `waves` random cosines (random Fourier features: wave vectors from the covariance's
// spectrum, N(0, I / l^2), uniform phases), so that its value and its derivatives are cheap anywhere.
// Over a region far larger than l its mean square is sigma^2 per axis exactly, whatever the draw.
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"

namespace lidarloop {

struct SlamMapErrorConfig {
  // HD-map vendors state 10-20 cm absolute accuracy for maps built from GNSS-anchored fleet data (the
  // figure the industry quotes for HERE HD Live Map and TomTom HD Map; Liu, Wang and Zhang, "High
  // Definition Map for Automated Driving: Overview and Analysis", J. Navigation 73(2), 2020, survey the
  // same decimetre range). The middle of the range, 15 cm, taken as the horizontal RMS (assumption: the
  // statements do not say whether they mean RMS or a 95 % bound).
  double absolute_sigma_m = 0.15;
  // Assumption, "a few centimetres over tens of metres": 3 cm horizontal RMS between two places 20 m
  // apart, 0.15 % of the distance. Pure LiDAR odometry drifts 0.5-1 % of the distance travelled
  // (KITTI odometry benchmark, LOAM about 0.55 % over 100-800 m segments); with loop closures and
  // anchors a pose graph keeps a few times less over a block. Gives a correlation length of about 100 m.
  double relative_sigma_m = 0.03;
  double relative_over_m = 20.0;
  // Not a physical figure: the number of cosines the field is drawn from. The field's relative error
  // over a given distance varies from one draw to the next by about sqrt(2 / waves) of itself (6 %).
  int waves = 512;

  std::string describe() const;  // every field as text, for the map cache key
};

// The field's correlation length l (see above), m. Throws std::invalid_argument unless
// 0 < relative_sigma_m < sqrt(2) absolute_sigma_m and the distances are positive.
double slam_correlation_length(const SlamMapErrorConfig& config);

// One draw of the map's error field.
class SlamErrorField {
 public:
  SlamErrorField() = default;
  SlamErrorField(const SlamMapErrorConfig& config, std::mt19937_64& rng);

  // The error at p: (east, north) and, as the heading error, the field's local rotation
  // (d e_north / d east - d e_east / d north) / 2, the angle a rigid scan placed there is turned by
  // (its standard deviation is absolute_sigma_m / (2 l)).
  Pose2d at(const Eigen::Vector2d& p) const;

 private:
  struct Wave {
    Eigen::Vector2d k;
    double phase;
  };
  std::vector<Wave> east_, north_;
  double amplitude_ = 0;
};

}  // namespace lidarloop
