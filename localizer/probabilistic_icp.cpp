#include "localizer/probabilistic_icp.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace lidarloop {

// ---------------------------------------------------------------------------------------------------
// The SVD step

Pose2d fit_rigid_2d(const std::vector<Eigen::Vector2d>& src, const std::vector<Eigen::Vector2d>& dst,
                    const std::vector<double>* weights) {
  if (src.size() != dst.size() || (weights && weights->size() != src.size()))
    throw std::invalid_argument("fit_rigid_2d: src, dst and weights must have the same size");
  double total = 0;
  Eigen::Vector2d cs = Eigen::Vector2d::Zero(), cd = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    const double w = weights ? (*weights)[i] : 1.0;
    total += w;
    cs += w * src[i];
    cd += w * dst[i];
  }
  if (!(total > 0)) return {};
  cs /= total;
  cd /= total;
  // Cross-covariance H = sum w s' d'^T; the optimal rotation of the SVD method is atan2 of its
  // antisymmetric over its symmetric part (Kabsch in 2-D: always a proper rotation).
  double dot = 0, cross = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const double w = weights ? (*weights)[i] : 1.0;
    const Eigen::Vector2d s = src[i] - cs, d = dst[i] - cd;
    dot += w * (s.x() * d.x() + s.y() * d.y());
    cross += w * (s.x() * d.y() - s.y() * d.x());
  }
  Pose2d t{0, 0, std::atan2(cross, dot)};  // a single pair: atan2(0, 0) = 0, translation only
  const Eigen::Vector2d rotated = t.apply(cs);
  t.x = cd.x() - rotated.x();
  t.y = cd.y() - rotated.y();
  return t;
}

// ---------------------------------------------------------------------------------------------------
// ICP core, shared by plain ICP (0/1 weights) and M-ICP (biweight)

namespace {

// Scores t: a curb is an inlier when its nearest map point is within the gate and weight(d) > 0.
template <class WeightFn>
void score(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, double gate, WeightFn weight,
           IcpResult& result) {
  double sum_squared = 0;
  size_t inliers = 0;
  const PoseApplier t(result.t);
  for (const auto& c : curbs) {
    const double d = map.nearest_within(t(c), gate).second;
    if (d <= gate && weight(d) > 0) {
      ++inliers;
      sum_squared += d * d;
    }
  }
  result.inliers = inliers;
  result.rmse = inliers ? std::sqrt(sum_squared / double(inliers)) : 0.0;
  result.outlier_ratio = curbs.empty() ? 1.0 : 1.0 - double(inliers) / double(curbs.size());
}

// `gate`: no correspondence beyond it; the weight function may still drop nearer ones.
template <class WeightFn>
IcpResult run_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial,
                  const IcpParams& params, double gate, WeightFn weight) {
  IcpResult result;
  result.t = initial;
  if (curbs.empty() || map.empty()) return result;  // outlier_ratio 1: nothing matched

  std::vector<Eigen::Vector2d> src, dst;
  std::vector<double> w;
  src.reserve(curbs.size());
  dst.reserve(curbs.size());
  w.reserve(curbs.size());
  for (int it = 0; it < params.max_iterations; ++it) {
    src.clear();
    dst.clear();
    w.clear();
    const PoseApplier t(result.t);
    for (const auto& c : curbs) {
      const Eigen::Vector2d p = t(c);
      const auto [index, d] = map.nearest_within(p, gate);
      if (index == SIZE_MAX) continue;
      const double wi = weight(d);
      if (!(wi > 0)) continue;
      src.push_back(p);
      dst.push_back(map.points()[index]);
      w.push_back(wi);
    }
    if (src.empty()) break;  // nothing to pull on: keep the current transform
    // Eq. 9 minimised for fixed correspondences; the increment is applied on top of the current pose.
    const Pose2d delta = fit_rigid_2d(src, dst, &w);
    result.t = delta.compose(result.t);
    ++result.iterations;
    if (std::hypot(delta.x, delta.y) < params.convergence && std::abs(delta.yaw) < params.convergence) break;
  }
  score(map, curbs, gate, weight, result);
  return result;
}

// Unbiased uniform integer in [0, n) from the raw 64-bit engine output. std::uniform_int_distribution
// would do, but its algorithm differs between standard libraries; this keeps draws identical everywhere.
size_t draw_below(std::mt19937_64& rng, size_t n) {
  constexpr uint64_t kMax = std::mt19937_64::max();
  static_assert(std::mt19937_64::min() == 0 && kMax == std::numeric_limits<uint64_t>::max());
  const uint64_t range = n;
  const uint64_t excess = (kMax % range + 1) % range;  // 2^64 mod n: the top values that would bias
  uint64_t r = rng();
  while (r > kMax - excess) r = rng();
  return size_t(r % range);
}

}  // namespace

IcpResult icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial, const IcpParams& params,
              double reject_distance) {
  // Eq. 12: a curb farther than reject_distance from the map is an outlier and takes no part in the fit.
  const double gate = std::min(params.max_correspondence, reject_distance);
  return run_icp(map, curbs, initial, params, gate, [](double) { return 1.0; });
}

IcpResult m_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial,
                const MIcpParams& params) {
  const double b = params.biweight_b, scale = params.scale_m;
  // IRLS weight of Eq. 22: rho'(u)/u = (1 - (u/B)^2)^2 inside B, 0 outside (rho is flat there).
  const double gate = std::min(params.icp.max_correspondence, b * scale);
  return run_icp(map, curbs, initial, params.icp, gate, [b, scale](double d) {
    const double u = d / scale;
    if (!(std::abs(u) < b)) return 0.0;
    const double v = 1.0 - (u / b) * (u / b);
    return v * v;
  });
}

// ---------------------------------------------------------------------------------------------------
// Probabilistic ICP

Pose2d fuse_hypotheses(const std::vector<IcpHypothesis>& hypotheses, double outlier_temperature) {
  if (hypotheses.empty()) return {};
  double best = 1.0;
  for (const auto& h : hypotheses) best = std::min(best, h.outlier_ratio);
  double total = 0, x = 0, y = 0, s = 0, c = 0;
  for (const auto& h : hypotheses) {
    // Eq. 13 read as "fewer outliers, more weight" (see ProbabilisticIcpParams).
    const double excess = h.outlier_ratio - best;
    const double w = outlier_temperature > 0 ? std::exp(-excess / outlier_temperature) : (excess <= 0 ? 1.0 : 0.0);
    total += w;
    x += w * h.t.x;
    y += w * h.t.y;
    // Angles are averaged as unit vectors so that +179 and -179 deg average to 180, not 0.
    s += w * std::sin(h.t.yaw);
    c += w * std::cos(h.t.yaw);
  }
  return {x / total, y / total, std::atan2(s, c)};
}

IcpResult probabilistic_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial,
                            const ProbabilisticIcpParams& params, std::mt19937_64& rng) {
  IcpResult result;
  result.t = initial;
  if (curbs.empty() || map.empty()) return result;

  const size_t n = curbs.size();
  const size_t n_p = std::clamp<size_t>(size_t(std::max(params.n_p, 1)), 1, n);
  // With n_p >= n every draw is the whole set and every iteration would be identical.
  const int n_t = n_p == n ? 1 : std::max(params.n_t, 1);

  // Draw every sample first, in a fixed order (partial Fisher-Yates from a fresh 0..n-1 each time), so
  // the n_t iterations below are independent of each other and of execution order.
  std::vector<std::vector<size_t>> samples(static_cast<size_t>(n_t));
  std::vector<size_t> order(n);
  for (auto& sample : samples) {
    std::iota(order.begin(), order.end(), size_t{0});
    for (size_t k = 0; k < n_p; ++k) std::swap(order[k], order[k + draw_below(rng, n - k)]);
    sample.assign(order.begin(), order.begin() + std::ptrdiff_t(n_p));
  }

  // The draws are independent and each writes only its own slot, so they run in parallel and the
  // fused result does not depend on the thread count or the schedule.
  std::vector<IcpHypothesis> hypotheses(samples.size());
  tbb::parallel_for(size_t{0}, samples.size(), [&](size_t i) {
    std::vector<Eigen::Vector2d> subset;
    subset.reserve(samples[i].size());
    for (size_t k : samples[i]) subset.push_back(curbs[k]);
    // Local ICP: a rough T_l,i from the subset (no rejection: with n_p points, every one counts).
    const IcpResult local = icp(map, subset, initial, params.local);
    // Global ICP from T_l,i on all curbs with Eq. 12 rejection at d_g -> T_g,i and its outlier ratio.
    const IcpResult global = icp(map, curbs, local.t, params.global, params.d_g);
    hypotheses[i] = {global.t, global.outlier_ratio};
  });

  result.t = fuse_hypotheses(hypotheses, params.outlier_softness_curbs / double(n));  // Eq. 13
  result.iterations = n_t;
  const double d_g = params.d_g;
  score(
      map, curbs, std::min(d_g, params.global.max_correspondence), [](double) { return 1.0; }, result);
  return result;
}

}  // namespace lidarloop
