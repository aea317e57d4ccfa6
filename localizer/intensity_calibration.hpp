#pragma once
// Beyond the paper: each laser's intensity response, calibrated online against the map's intensity layer.
//
// The lasers of a multi-beam unit read different intensities off the same surface (Levinson & Thrun,
// "Unsupervised calibration for multi-beam lasers", ISER 2010), and the map was made by another unit.
// Uncorrected, a laser that reads 2 counts high paints its ring onto S around the car scan after scan;
// on asphalt of about 10 counts that ring is as strong as the paint, and APS matches the rings instead
// of the road (dynamic_campus under the `typical` sensor: longitudinal RMSE 0.11 -> 1.6 m).
//
// Each laser's reading y of a surface the map says reads x is modelled as y = g x + o. (g, o) are the
// least-squares fit over the ground points of past scans, placed with the filter's pose, with
// exponential forgetting, and a prior of `prior_points` dark and `prior_points` bright pseudo-returns
// read true (g = 1, o = 0), so a laser that has seen only asphalt keeps its gain near one. Scans are
// corrected by inverting the fit before they enter S: x = (y - o) / g.
//
// At a cold start the pose is metres off and the map cannot be asked what a point should read. The
// lasers can still be made to agree with each other: most of a scan's road surface is asphalt, so each
// laser's median ground reading against the median of all of them is that laser's offset on asphalt
// (a pose-free pair, weighted as the points behind it), until the filter knows where it is.
#include <array>
#include <cstddef>
#include <cstdint>

namespace lidarloop {

struct IntensityCalibrationParams {
  bool enabled = true;
  double forgetting = 0.99;  // per scan: the fit's memory is about 100 scans (10 s at 10 Hz)
  // The prior: this many pseudo-returns at each of two intensities, read true.
  double prior_points = 200;
  double prior_dark = 10;    // counts: asphalt
  double prior_bright = 50;  // counts: lane paint
  // Learn only where the map's cell is this well observed, and only while the filter's position is known
  // this well (1 sigma, m, on either axis): a point placed metres off compares unlike with unlike.
  int min_map_count = 3;
  double max_position_sigma_m = 0.5;
  int point_stride = 4;      // learn from every n-th ground point (the fit needs hundreds, a scan has thousands)
  int min_ring_points = 50;  // pose-free: a laser's median ground reading from at least this many points
  double min_gain = 0.5, max_gain = 2.0;
};

class IntensityCalibration {
 public:
  static constexpr int kMaxLasers = 128;

  explicit IntensityCalibration(const IntensityCalibrationParams& params = {});

  // One scan's pairs: `ring` read `reading` where the map's cell has mean `map_mean`. Call once per pair,
  // then end_scan() once.
  void add(int ring, double reading, double map_mean, double weight = 1);
  void end_scan();  // applies the forgetting and refits every laser

  // The reading of `ring` as the map's unit would have read it (unchanged for an unknown ring).
  double correct(int ring, double reading) const;
  double gain(int ring) const { return valid(ring) ? fit_[std::size_t(ring)].gain : 1.0; }
  double offset(int ring) const { return valid(ring) ? fit_[std::size_t(ring)].offset : 0.0; }

 private:
  struct Sums {
    double n = 0, x = 0, y = 0, xx = 0, xy = 0;
  };
  struct Fit {
    double gain = 1, offset = 0;
  };
  static bool valid(int ring) { return ring >= 0 && ring < kMaxLasers; }

  IntensityCalibrationParams params_;
  std::array<Sums, kMaxLasers> sums_{};
  std::array<Fit, kMaxLasers> fit_{};
};

}  // namespace lidarloop
