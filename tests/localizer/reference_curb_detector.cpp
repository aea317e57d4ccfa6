// The oracle for localizer/curb_detector.cpp: see reference_curb_detector.hpp. This is that file as it
// stood before commit 0235f81 (git show 0235f81^:localizer/curb_detector.cpp), with only its namespace,
// its function's name and clang-format's line breaks changed, and one change of behaviour made in both
// detectors since: the rise is read where each flat stretch, carried along its own tilt, meets the
// step (half_median_slope). Below it, the comparison the tests make with it.
#include "reference_curb_detector.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <utility>

namespace lidarloop::test {

namespace {

constexpr int kMaxRings = 64;
constexpr double kMinGap = 0.15, kGapSteps = 4, kAzimuthStep = 0.0029;  // m, -, rad
// The cheap test on means lets through anything within this factor of the limits; the exact test on
// medians then decides. Means move with a stray return, so the margin is generous.
constexpr double kPrefilterSlack = 2.0;

// One laser's ground-looking points in azimuth order, with what makes stretch queries O(1): the
// horizontal arc length up to each point, prefix sums of z and z^2, and a segment number that changes
// at every gap (missing returns: no curb can be read across one).
struct Ring {
  std::vector<const Eigen::Vector3d*> p;
  std::vector<double> s, z_sum, z2_sum;
  std::vector<int> segment;

  void finish() {
    const size_t n = p.size();
    s.assign(n, 0.0);
    segment.assign(n, 0);
    z_sum.assign(n + 1, 0.0);
    z2_sum.assign(n + 1, 0.0);
    for (size_t k = 0; k < n; ++k) {
      const double z = p[k]->z();
      z_sum[k + 1] = z_sum[k] + z;
      z2_sum[k + 1] = z2_sum[k] + z * z;
      if (k == 0) continue;
      const double d = (p[k]->head<2>() - p[k - 1]->head<2>()).norm();
      // A gap of a few azimuth steps (0.166 deg at 10 Hz) at this range means missing returns.
      const double max_gap = std::max(kMinGap, kGapSteps * p[k - 1]->head<2>().norm() * kAzimuthStep);
      s[k] = s[k - 1] + d;
      segment[k] = segment[k - 1] + (d > max_gap ? 1 : 0);
    }
  }
  // Mean and spread of z over points [a, b] (either order).
  void moments(size_t a, size_t b, double& mean, double& sigma) const {
    if (a > b) std::swap(a, b);
    const double n = double(b - a + 1);
    mean = (z_sum[b + 1] - z_sum[a]) / n;
    sigma = std::sqrt(std::max(0.0, (z2_sum[b + 1] - z2_sum[a]) / n - mean * mean));
  }
};

// For every point, the index `length` metres of arc ahead of it (forward) or behind it (backward)
// within its segment: -1 where the ring ends or has a gap first. Two pointers, O(n).
std::vector<long> reach(const Ring& r, double length, bool forward) {
  const long n = long(r.p.size());
  std::vector<long> out(size_t(n), -1);
  if (forward) {
    long k = 0;
    for (long i = 0; i < n; ++i) {
      k = std::max(k, i + 1);
      while (k < n && r.s[size_t(k)] - r.s[size_t(i)] < length) ++k;
      if (k < n && r.segment[size_t(k)] == r.segment[size_t(i)]) out[size_t(i)] = k;
    }
  } else {
    long k = -1;  // the largest index with s[i] - s[k] >= length
    for (long i = 0; i < n; ++i) {
      while (k + 1 < i && r.s[size_t(i)] - r.s[size_t(k + 1)] >= length) ++k;
      if (k >= 0 && r.segment[size_t(k)] == r.segment[size_t(i)]) out[size_t(i)] = k;
    }
  }
  return out;
}

struct Stretch {
  double median_z, sigma_z;
  double slope, mid_s;  // dz/ds along the ring, and the arc length the median stands for

  double height_at(double s) const { return median_z + slope * (s - mid_s); }
};

// The tilt of ring points [a, b] (a < b): from the medians of its two halves, so the few points of
// a curb face at the stretch's end do not tilt it.
double half_median_slope(const Ring& r, size_t a, size_t b, std::vector<double>& scratch) {
  if (b - a < 3) return 0;
  const size_t m = a + (b - a) / 2;  // the first half is [a, m], the second [m + 1, b]
  auto median_z = [&](size_t from, size_t to) {
    scratch.clear();
    for (size_t k = from; k <= to; ++k) scratch.push_back(r.p[k]->z());
    std::nth_element(scratch.begin(), scratch.begin() + long(scratch.size() / 2), scratch.end());
    return scratch[scratch.size() / 2];
  };
  const double run = (r.s[m + 1] + r.s[b]) / 2 - (r.s[a] + r.s[m]) / 2;
  return run > 0 ? (median_z(m + 1, b) - median_z(a, m)) / run : 0.0;
}

// Height statistics of ring points [a, b] (either order): median (robust to a stray return), the
// spread about it, and the tilt, so the rise is read where each stretch meets the step.
Stretch stretch(const Ring& r, size_t a, size_t b, std::vector<double>& scratch) {
  if (a > b) std::swap(a, b);
  scratch.clear();
  for (size_t k = a; k <= b; ++k) scratch.push_back(r.p[k]->z());
  std::nth_element(scratch.begin(), scratch.begin() + long(scratch.size() / 2), scratch.end());
  const double median = scratch[scratch.size() / 2];
  double sum2 = 0;
  for (double v : scratch) sum2 += (v - median) * (v - median);
  const double sigma = std::sqrt(sum2 / double(scratch.size()));
  return {median, sigma, half_median_slope(r, a, b, scratch), (r.s[a] + r.s[b]) / 2};
}

}  // namespace

std::vector<Eigen::Vector2d> reference_detect_curbs(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<uint16_t>& rings, const CurbDetectorParams& p) {
  // Split the scan into rings, keeping firing (azimuth) order; drop what cannot be a curb.
  std::vector<Ring> by_ring(kMaxRings);
  for (size_t i = 0; i < points.size() && i < rings.size(); ++i) {
    const Eigen::Vector3d& q = points[i];
    if (!q.allFinite() || rings[i] >= kMaxRings) continue;
    const double range = q.head<2>().norm();
    if (range > p.max_range || range < 1.0 || q.z() > p.max_ground_height) continue;
    by_ring[rings[i]].p.push_back(&q);
  }
  std::vector<Eigen::Vector2d> curbs;
  std::vector<double> scratch;
  for (Ring& ring : by_ring) {
    if (ring.p.size() < 5) continue;
    ring.finish();
    const std::vector<long> step_ahead = reach(ring, p.step_length, true),
                            step_behind = reach(ring, p.step_length, false);
    const std::vector<long> flat_ahead = reach(ring, p.flat_length, true),
                            flat_behind = reach(ring, p.flat_length, false);
    for (size_t i = 0; i < ring.p.size(); ++i) {
      // The rise: within step_length along the ring (either direction), the height climbs by a curb's
      // height; the stretch before i is flat road, the stretch after the rise flat sidewalk.
      for (int dir : {+1, -1}) {
        const long top = dir > 0 ? step_ahead[i] : step_behind[i];
        if (top < 0) continue;
        const long before = dir > 0 ? flat_behind[i] : flat_ahead[i];
        const long after = dir > 0 ? flat_ahead[size_t(top)] : flat_behind[size_t(top)];
        if (before < 0 || after < 0) continue;
        // Cheap test on the means first: most of a scan is flat road and fails here.
        double road_mean, road_sigma, walk_mean, walk_sigma;
        ring.moments(size_t(before), i, road_mean, road_sigma);
        ring.moments(size_t(top), size_t(after), walk_mean, walk_sigma);
        const double mean_rise = walk_mean - road_mean;
        if (mean_rise < p.min_height / kPrefilterSlack || mean_rise > p.max_height * kPrefilterSlack) continue;
        // Road before i, sidewalk after the rise: both flat, the sidewalk a curb's height higher.
        const Stretch road = stretch(ring, size_t(before), i, scratch);
        const Stretch walkway = stretch(ring, size_t(top), size_t(after), scratch);
        const double rise = walkway.height_at(ring.s[size_t(top)]) - road.height_at(ring.s[i]);
        if (rise < p.min_height || rise > p.max_height) continue;
        if (road.sigma_z > p.max_flat_roughness || walkway.sigma_z > p.max_flat_roughness) continue;
        // The foot of the rise: the last point still at road height.
        size_t foot = i;
        for (long k = long(i) + dir; k != top; k += dir)
          if (ring.p[size_t(k)]->z() - road.median_z < p.min_height / 2) foot = size_t(k);
        curbs.push_back(ring.p[foot]->head<2>());
        i = size_t(std::max<long>(long(i), top));  // one detection per rise
        break;
      }
    }
  }
  return curbs;
}

// ---- Comparing the fast detector's curbs with these ----

namespace {

using Bits = std::pair<uint64_t, uint64_t>;

Bits bits(const Eigen::Vector2d& c) { return {std::bit_cast<uint64_t>(c.x()), std::bit_cast<uint64_t>(c.y())}; }

std::string show(const Eigen::Vector2d& c) {
  char text[80];
  std::snprintf(text, sizeof text, "(%.17g, %.17g)", c.x(), c.y());
  return text;
}

// The points of `a` that `b` lacks, counted with multiplicity.
std::vector<Eigen::Vector2d> missing_from(const std::vector<Eigen::Vector2d>& a,
                                          const std::vector<Eigen::Vector2d>& b) {
  std::map<Bits, int> count;
  for (const auto& c : b) ++count[bits(c)];
  std::vector<Eigen::Vector2d> missing;
  for (const auto& c : a)
    if (count[bits(c)]-- <= 0) missing.push_back(c);
  return missing;
}

}  // namespace

std::string curb_difference(const std::vector<Eigen::Vector2d>& fast, const std::vector<Eigen::Vector2d>& reference) {
  size_t first = 0;
  while (first < fast.size() && first < reference.size() && bits(fast[first]) == bits(reference[first])) ++first;
  if (first == fast.size() && first == reference.size()) return "";
  std::ostringstream out;
  out << "the fast detector found " << fast.size() << " curbs, the reference " << reference.size()
      << "; they first differ at index " << first;
  const auto extra = missing_from(fast, reference), lacking = missing_from(reference, fast);
  if (extra.empty() && lacking.empty()) out << ": the same curbs, in another order";
  if (!extra.empty()) out << "; " << extra.size() << " only the fast one found, first " << show(extra.front());
  if (!lacking.empty()) out << "; " << lacking.size() << " only the reference found, first " << show(lacking.front());
  return out.str();
}

}  // namespace lidarloop::test
