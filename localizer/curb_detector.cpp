#include "localizer/curb_detector.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop {

namespace {

constexpr int kMaxRings = 64;
constexpr double kMinGap = 0.15, kGapSteps = 4, kAzimuthStep = 0.0029;  // m, -, rad

struct Stretch {
  double median_z, sigma_z;
};

// Height statistics of ring points [first, last]: median (robust to a stray return) and spread.
Stretch stretch(const std::vector<const Eigen::Vector3d*>& ring, size_t first, size_t last) {
  std::vector<double> z;
  for (size_t k = first; k <= last; ++k) z.push_back(ring[k]->z());
  std::nth_element(z.begin(), z.begin() + long(z.size() / 2), z.end());
  const double median = z[z.size() / 2];
  double sum2 = 0;
  for (double v : z) sum2 += (v - median) * (v - median);
  return {median, std::sqrt(sum2 / double(z.size()))};
}

// Walks from `i` along the ring (step +1 or -1) until `length` metres of horizontal distance are
// covered; returns the index reached, or -1 when the ring ends or has a gap first.
long walk(const std::vector<const Eigen::Vector3d*>& ring, size_t i, int step, double length, double max_gap) {
  double covered = 0;
  long k = long(i);
  while (covered < length) {
    const long next = k + step;
    if (next < 0 || next >= long(ring.size())) return -1;
    const double d = (ring[size_t(next)]->head<2>() - ring[size_t(k)]->head<2>()).norm();
    if (d > max_gap) return -1;
    covered += d;
    k = next;
  }
  return k;
}

}  // namespace

std::vector<Eigen::Vector2d> detect_curbs(const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<uint16_t>& rings, const CurbDetectorParams& p) {
  // Split the scan into rings, keeping firing (azimuth) order; drop what cannot be a curb.
  std::vector<std::vector<const Eigen::Vector3d*>> by_ring(kMaxRings);
  for (size_t i = 0; i < points.size() && i < rings.size(); ++i) {
    const Eigen::Vector3d& q = points[i];
    if (!q.allFinite() || rings[i] >= kMaxRings) continue;
    const double range = q.head<2>().norm();
    if (range > p.max_range || range < 1.0 || q.z() > p.max_ground_height) continue;
    by_ring[rings[i]].push_back(&q);
  }
  std::vector<Eigen::Vector2d> curbs;
  for (const auto& ring : by_ring) {
    if (ring.size() < 5) continue;
    for (size_t i = 0; i < ring.size(); ++i) {
      // The rise: within step_length ahead (either direction along the ring), the height climbs by a
      // curb's height; the stretch before i is flat road, the stretch after the rise flat sidewalk.
      for (int dir : {+1, -1}) {
        const double range = ring[i]->head<2>().norm();
        // A gap of a few azimuth steps (0.166 deg at 10 Hz) means missing returns: no curb across it.
        const double max_gap = std::max(kMinGap, kGapSteps * range * kAzimuthStep);
        const long top = walk(ring, i, dir, p.step_length, max_gap);
        if (top < 0) continue;
        const long before = walk(ring, i, -dir, p.flat_length, max_gap);
        const long after = walk(ring, size_t(top), dir, p.flat_length, max_gap);
        if (before < 0 || after < 0) continue;
        // Road before i, sidewalk after the rise: both flat, the sidewalk a curb's height higher.
        const Stretch road = stretch(ring, std::min(size_t(before), i), std::max(size_t(before), i));
        const Stretch walkway = stretch(ring, std::min(size_t(top), size_t(after)), std::max(size_t(top), size_t(after)));
        const double rise = walkway.median_z - road.median_z;
        if (rise < p.min_height || rise > p.max_height) continue;
        if (road.sigma_z > p.max_flat_roughness || walkway.sigma_z > p.max_flat_roughness) continue;
        // The foot of the rise: the last point still at road height.
        size_t foot = i;
        for (long k = long(i) + dir; k != top; k += dir)
          if (ring[size_t(k)]->z() - road.median_z < p.min_height / 2) foot = size_t(k);
        curbs.push_back(ring[foot]->head<2>());
        i = size_t(std::max<long>(long(i), top));  // one detection per rise
        break;
      }
    }
  }
  return curbs;
}

}  // namespace lidarloop
