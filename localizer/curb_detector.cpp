#include "localizer/curb_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

namespace lidarloop {

namespace {

constexpr int kMaxRings = 64;
constexpr double kMinGap = 0.15, kGapSteps = 4, kAzimuthStep = 0.0029;  // m, -, rad
constexpr double kMinRange = 1.0;                                       // m: about the sensor's own minimum range
constexpr size_t kMinRingPoints = 5;  // fewer cannot hold a road, a rise and a sidewalk
constexpr int kNoSegment = -1;        // the segment of the sentinel past a ring's last point
constexpr long kLookahead = 3;        // points a walk along a ring tests at once (see first_ahead)
constexpr long kWalks = 4;            // walks along a ring run side by side (see walk_ahead)
// The cheap test on means lets through anything within this factor of the limits; the exact test on
// medians then decides. Means move with a stray return, so the margin is generous.
constexpr double kPrefilterSlack = 2.0;
// The roughness pre-test may only reject what the median test would reject too, rounding included:
// it allows a relative margin and an absolute one (for a zero limit) far above its own rounding.
constexpr double kRoundingSlack = 1e-9, kRoundingFloor = 1e-12;  // -, m^2

// The scan's ground-looking points grouped by ring, ring after ring, each in firing (azimuth) order.
// The scan interleaves the rings, so walking one ring in place would stride across all the others.
struct RingPoints {
  // range: horizontal distance from the vehicle. Arrays left uninitialised (new double[n], not a
  // vector): every place a ring's range covers is written, the rest never read, and zeroing four
  // scan-sized arrays first was a few percent of the detector.
  std::unique_ptr<double[]> x, y, z, range;
  std::array<size_t, kMaxRings> begin{}, end{};  // ring r is [begin[r], end[r])
};

// Drops what cannot be a curb and places each ring's points together, in one pass over the scan:
// every ring has room for all its returns, and each point is written at its ring's next free place,
// which moves on only if the point passes. So no branch to mispredict on the mix of ground and the rest.
// `level` gives each point as the detector reads it (see detect_curbs' ground).
template <class Level>
RingPoints group_by_ring(const std::vector<Eigen::Vector3d>& points, const std::vector<uint16_t>& rings,
                         const CurbDetectorParams& p, const Level& level) {
  constexpr size_t kDiscard = kMaxRings;  // where rings beyond kMaxRings write: one place, never kept
  const size_t n = std::min(points.size(), rings.size());
  std::array<size_t, kMaxRings + 1> count{}, next{};
  for (size_t i = 0; i < n; ++i) ++count[std::min<size_t>(rings[i], kDiscard)];
  for (size_t r = 1; r <= kDiscard; ++r) next[r] = next[r - 1] + count[r - 1];
  RingPoints g;
  for (auto* v : {&g.x, &g.y, &g.z, &g.range}) v->reset(new double[next[kDiscard] + 1]);
  std::copy_n(next.begin(), kMaxRings, g.begin.begin());
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d q = level(points[i]);
    const size_t ring = std::min<size_t>(rings[i], kDiscard);
    const double range = q.head<2>().norm();
    const bool keep = q.allFinite() && ring != kDiscard && !(range > p.max_range) && !(range < kMinRange) &&
                      !(q.z() > p.max_ground_height);
    const size_t k = next[ring];
    g.x[k] = q.x();
    g.y[k] = q.y();
    g.z[k] = q.z();
    g.range[k] = range;
    next[ring] = k + keep;
  }
  std::copy_n(next.begin(), kMaxRings, g.end.begin());
  return g;
}

// One laser's ground-looking points (a view into RingPoints), with what makes stretch queries O(1):
// the horizontal arc length up to each point, prefix sums of z, and a segment number that changes at
// every gap (missing returns: no curb can be read across one). Past the last point, s and segment hold
// sentinels (an arc length no walk reaches, a segment no point is in) so walks need no end checks. The
// arrays are reused ring after ring.
struct Ring {
  const double *x = nullptr, *y = nullptr, *z = nullptr;
  size_t n = 0;
  std::vector<double> s, z_sum;
  std::vector<int> segment;

  void load(const RingPoints& g, int ring) {
    const size_t b = g.begin[size_t(ring)];
    n = g.end[size_t(ring)] - b;
    x = g.x.get() + b, y = g.y.get() + b, z = g.z.get() + b;
    const double* range = g.range.get() + b;
    s.resize(n + kLookahead);
    segment.resize(n + 1);
    z_sum.resize(n + 1);
    std::fill(s.begin() + long(n), s.end(), std::numeric_limits<double>::infinity());
    segment[n] = kNoSegment;
    s[0] = 0;
    segment[0] = 0;
    z_sum[0] = 0;
    for (size_t k = 0; k < n; ++k) {
      z_sum[k + 1] = z_sum[k] + z[k];
      if (k == 0) continue;
      const double dx = x[k] - x[k - 1], dy = y[k] - y[k - 1];
      const double d = std::sqrt(dx * dx + dy * dy);
      // A gap of a few azimuth steps (0.166 deg at 10 Hz) at this range means missing returns.
      const double max_gap = std::max(kMinGap, kGapSteps * range[k - 1] * kAzimuthStep);
      s[k] = s[k - 1] + d;
      segment[k] = segment[k - 1] + (d > max_gap ? 1 : 0);
    }
  }
  // Mean of z over points [a, b] (either order).
  double mean(size_t a, size_t b) const {
    if (a > b) std::swap(a, b);
    return (z_sum[b + 1] - z_sum[a]) / double(b - a + 1);
  }
  // k (a point, the end sentinel or -1) if it lies in point i's segment, else -1.
  long if_same_segment(long k, long i) const { return k >= 0 && segment[size_t(k)] == segment[size_t(i)] ? k : -1; }
};

// From k (at most the end sentinel), the first index whose arc length is `length` or more past s_i.
// Walks move by a point or two per step, unpredictably (the arc between neighbours carries the range
// noise), so this tests the next kLookahead points at once and counts, with no branch to mispredict.
// Arc length rises along the ring: the points that pass come first, and their count is the step.
long first_ahead(const Ring& r, long k, double s_i, double length) {
  for (;;) {
    long step = 0;
    for (long j = 0; j < kLookahead; ++j) step += r.s[size_t(k + j)] - s_i < length;
    k += step;
    if (step < kLookahead) return k;
  }
}

// Every point's first_ahead (the end sentinel where the ring ends first), by two pointers. Each step of
// a walk starts where the last one ended, so it waits for it: the ring is cut into kWalks pieces walked
// side by side, independent, for the processor to overlap (unrolled, so their positions stay in
// registers).
void walk_ahead(const Ring& r, double length, std::vector<long>& ahead) {
  const long n = long(r.n), piece = n / kWalks;  // the last walk also takes the remainder
  ahead.resize(r.n);
  std::array<long, kWalks> k{};
  for (long t = 0; t < piece; ++t) {
#pragma GCC unroll kWalks
    for (long w = 0; w < kWalks; ++w) {
      const long i = w * piece + t;
      k[size_t(w)] = first_ahead(r, std::max(k[size_t(w)], i + 1), r.s[size_t(i)], length);
      ahead[size_t(i)] = k[size_t(w)];
    }
  }
  for (long i = kWalks * piece, last = k[kWalks - 1]; i < n; ++i)
    ahead[size_t(i)] = last = first_ahead(r, std::max(last, i + 1), r.s[size_t(i)], length);
}

// Every point's last index before it whose arc length is `length` or more short of its own (-1 if
// none), by two pointers.
void walk_behind(const Ring& r, double length, std::vector<long>& behind) {
  behind.resize(r.n);
  long k = -1;
  for (size_t i = 0; i < r.n; ++i) {
    while (k + 1 < long(i) && r.s[i] - r.s[size_t(k + 1)] >= length) ++k;
    behind[i] = k;
  }
}

// walk_behind's answer read off walk_ahead's, with no search: k is that far behind i exactly when i is
// that far ahead of k, so i's answer is the last k whose walk_ahead is i or before.
void invert_ahead(const std::vector<long>& ahead, std::vector<long>& behind) {
  const size_t n = ahead.size();
  behind.assign(n + 1, -1);  // the last place takes the points whose reach is the ring's end
  for (size_t k = 0; k < n; ++k) behind[size_t(ahead[k])] = long(k);
  for (size_t i = 1; i < n; ++i) behind[i] = std::max(behind[i], behind[i - 1]);
  behind.pop_back();
}

// walk_behind, by invert_ahead where the two agree: they ask whether the same difference of arc lengths
// reaches `length`, in opposite senses, which differ only if one side is NaN (a NaN length, or arc
// lengths that overflowed).
void reach_behind(const Ring& r, double length, const std::vector<long>& ahead, std::vector<long>& behind) {
  if (std::isnan(length) || !std::isfinite(r.s[r.n - 1]))
    walk_behind(r, length, behind);
  else
    invert_ahead(ahead, behind);
}

// For every point, the index step_length or flat_length metres of arc ahead of it or behind it within
// its segment: -1 where the ring ends or has a gap first. O(n), arrays reused ring after ring.
struct Reaches {
  std::vector<long> step_ahead, step_behind, flat_ahead, flat_behind;

  void compute(const Ring& r, const CurbDetectorParams& p) {
    walk_ahead(r, p.step_length, step_ahead);
    walk_ahead(r, p.flat_length, flat_ahead);
    reach_behind(r, p.step_length, step_ahead, step_behind);
    reach_behind(r, p.flat_length, flat_ahead, flat_behind);
    for (size_t i = 0; i < r.n; ++i) {
      step_ahead[i] = r.if_same_segment(step_ahead[i], long(i));
      flat_ahead[i] = r.if_same_segment(flat_ahead[i], long(i));
      step_behind[i] = r.if_same_segment(step_behind[i], long(i));
      flat_behind[i] = r.if_same_segment(flat_behind[i], long(i));
    }
  }
};

// The reaches as seen from a point looking one way along the ring (dir): the rise runs from the point
// to `step`'s index, the road lies back from the point and the sidewalk on from the top of the rise.
struct Direction {
  int dir;
  const long *step, *flat_back, *flat_on;
};

// Mean squared deviation of z over ring points [a, b] (either order) from their mean. The mean
// minimises the sum of squares, so this never exceeds the squared spread about the median: a stretch
// too rough by it is too rough for the median test as well, and this needs no sorting.
double spread_about_mean_sq(const Ring& r, size_t a, size_t b) {
  if (a > b) std::swap(a, b);
  const double n = double(b - a + 1);
  double sum = 0;
  for (size_t k = a; k <= b; ++k) sum += r.z[k];
  const double mean = sum / n;
  double sum2 = 0;
  for (size_t k = a; k <= b; ++k) sum2 += (r.z[k] - mean) * (r.z[k] - mean);
  return sum2 / n;
}

bool surely_rougher_than(const Ring& r, size_t a, size_t b, double max_roughness) {
  const double limit_sq = max_roughness * max_roughness;
  return spread_about_mean_sq(r, a, b) > limit_sq * (1 + kRoundingSlack) + kRoundingFloor;
}

struct Stretch {
  double median_z, sigma_z;
  double slope, mid_s;  // dz/ds along the ring, and the arc length the median stands for

  // The stretch's height carried along its own slope to arc length s.
  double height_at(double s) const { return median_z + slope * (s - mid_s); }
};

// The tilt of ring points [a, b] (a < b): from the medians of its two halves, so the few points of
// a curb face at the stretch's end do not tilt it.
double half_median_slope(const Ring& r, size_t a, size_t b, std::vector<double>& scratch) {
  if (b - a < 3) return 0;
  const size_t m = a + (b - a) / 2;  // the first half is [a, m], the second [m + 1, b]
  auto median_z = [&](size_t from, size_t to) {
    scratch.assign(r.z + from, r.z + to + 1);
    std::nth_element(scratch.begin(), scratch.begin() + long(scratch.size() / 2), scratch.end());
    return scratch[scratch.size() / 2];
  };
  const double run = (r.s[m + 1] + r.s[b]) / 2 - (r.s[a] + r.s[m]) / 2;
  return run > 0 ? (median_z(m + 1, b) - median_z(a, m)) / run : 0.0;
}

// Height statistics of ring points [a, b] (either order): median (robust to a stray return) and the
// spread about it. The tilt is left for tilt(): a stretch too rough to be flat needs none.
Stretch level_stretch(const Ring& r, size_t a, size_t b, std::vector<double>& scratch) {
  if (a > b) std::swap(a, b);
  scratch.assign(r.z + a, r.z + b + 1);
  std::nth_element(scratch.begin(), scratch.begin() + long(scratch.size() / 2), scratch.end());
  const double median = scratch[scratch.size() / 2];
  double sum2 = 0;
  for (double v : scratch) sum2 += (v - median) * (v - median);
  const double sigma = std::sqrt(sum2 / double(scratch.size()));
  return {median, sigma, 0.0, 0.0};
}

// The tilt of the stretch of ring points [a, b] (either order). A flat stretch may tilt (a crowned
// road, a sidewalk's cross-fall, the flare beside a curb ramp); the rise is read where each stretch
// meets the step, so a slope that runs on through road and sidewalk is not taken for a curb.
void tilt(const Ring& r, size_t a, size_t b, Stretch& stretch, std::vector<double>& scratch) {
  if (a > b) std::swap(a, b);
  stretch.slope = half_median_slope(r, a, b, scratch);
  stretch.mid_s = (r.s[a] + r.s[b]) / 2;
}

}  // namespace

std::vector<Eigen::Vector2d> detect_curbs(const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<uint16_t>& rings, const CurbDetectorParams& p,
                                          const std::optional<Plane>& ground) {
  // Split the scan into rings, keeping firing (azimuth) order; drop what cannot be a curb.
  const RingPoints by_ring =
      ground ? group_by_ring(points, rings, p, PlaneLeveller(*ground))
             : group_by_ring(points, rings, p, [](const Eigen::Vector3d& q) -> const Eigen::Vector3d& { return q; });
  std::vector<Eigen::Vector2d> curbs;
  std::vector<double> scratch;
  Ring ring;
  Reaches reach;
  for (int r = 0; r < kMaxRings; ++r) {
    if (by_ring.end[size_t(r)] - by_ring.begin[size_t(r)] < kMinRingPoints) continue;
    ring.load(by_ring, r);
    reach.compute(ring, p);
    const std::array<Direction, 2> directions = {
        Direction{+1, reach.step_ahead.data(), reach.flat_behind.data(), reach.flat_ahead.data()},
        Direction{-1, reach.step_behind.data(), reach.flat_ahead.data(), reach.flat_behind.data()}};
    for (size_t i = 0; i < ring.n; ++i) {
      // The rise: within step_length along the ring (either direction), the height climbs by a curb's
      // height; the stretch before i is flat road, the stretch after the rise flat sidewalk.
      for (const Direction& d : directions) {
        const long top = d.step[i];
        if (top < 0) continue;
        const long before = d.flat_back[i];
        const long after = d.flat_on[size_t(top)];
        if (before < 0 || after < 0) continue;
        // Cheap test on the means first: most of a scan is flat road and fails here.
        const double mean_rise = ring.mean(size_t(top), size_t(after)) - ring.mean(size_t(before), i);
        if (mean_rise < p.min_height / kPrefilterSlack || mean_rise > p.max_height * kPrefilterSlack) continue;
        // Then flatness without sorting, which turns away most of the rest.
        if (surely_rougher_than(ring, size_t(before), i, p.max_flat_roughness) ||
            surely_rougher_than(ring, size_t(top), size_t(after), p.max_flat_roughness))
          continue;
        // Road before i, sidewalk after the rise: both flat, the sidewalk a curb's height higher. The
        // flatness first: it needs no tilt, and the tests are all pass-or-skip, so their order does
        // not change what is found.
        Stretch road = level_stretch(ring, size_t(before), i, scratch);
        if (road.sigma_z > p.max_flat_roughness) continue;
        Stretch walkway = level_stretch(ring, size_t(top), size_t(after), scratch);
        if (walkway.sigma_z > p.max_flat_roughness) continue;
        tilt(ring, size_t(before), i, road, scratch);
        tilt(ring, size_t(top), size_t(after), walkway, scratch);
        const double rise = walkway.height_at(ring.s[size_t(top)]) - road.height_at(ring.s[i]);
        if (rise < p.min_height || rise > p.max_height) continue;
        // The foot of the rise: the last point still at road height.
        size_t foot = i;
        for (long k = long(i) + d.dir; k != top; k += d.dir)
          if (ring.z[size_t(k)] - road.median_z < p.min_height / 2) foot = size_t(k);
        curbs.emplace_back(ring.x[foot], ring.y[foot]);
        i = size_t(std::max<long>(long(i), top));  // one detection per rise
        break;
      }
    }
  }
  return curbs;
}

}  // namespace lidarloop
