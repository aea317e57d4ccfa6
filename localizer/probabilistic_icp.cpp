#include "localizer/probabilistic_icp.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include <nanoflann.hpp>

namespace lidarloop {

Eigen::Vector2d Transform2d::apply(const Eigen::Vector2d& p) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * p.x() - s * p.y() + x, s * p.x() + c * p.y() + y};
}

Transform2d Transform2d::compose(const Transform2d& b) const {
  const Eigen::Vector2d t = apply({b.x, b.y});
  return {t.x(), t.y(), wrap_angle(theta + b.theta)};
}

Transform2d Transform2d::inverse() const {
  const double c = std::cos(theta), s = std::sin(theta);
  // R^T (p - t): the translation is -R^T t.
  return {-(c * x + s * y), -(-s * x + c * y), wrap_angle(-theta)};
}

double wrap_angle(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);  // [-pi, pi]
  return a <= -std::numbers::pi ? a + 2 * std::numbers::pi : a;
}

// ---------------------------------------------------------------------------------------------------
// MapIndex

namespace {
struct PointsAdaptor {
  const std::vector<Eigen::Vector2d>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][int(dim)]; }
  template <class BBox> bool kdtree_get_bbox(BBox&) const { return false; }
};
constexpr int kLeafSize = 16;  // nanoflann's usual trade-off between tree depth and leaf scans
}  // namespace

struct MapIndex::Tree {
  PointsAdaptor adaptor;
  nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>, PointsAdaptor, 2> tree;
  explicit Tree(const std::vector<Eigen::Vector2d>* points)
      : adaptor{points}, tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {
    tree.buildIndex();
  }
};

MapIndex::MapIndex(std::vector<Eigen::Vector2d> points) : points_(std::move(points)) {
  // nanoflann cannot build over zero points; an empty map answers every query with "nothing".
  if (!points_.empty()) tree_ = std::make_unique<Tree>(&points_);
}
MapIndex::~MapIndex() = default;
// The tree reads the points through a pointer to the member vector: re-aim it after a move.
MapIndex::MapIndex(MapIndex&& other) noexcept : points_(std::move(other.points_)), tree_(std::move(other.tree_)) {
  if (tree_) tree_->adaptor.points = &points_;
}
MapIndex& MapIndex::operator=(MapIndex&& other) noexcept {
  points_ = std::move(other.points_);
  tree_ = std::move(other.tree_);
  if (tree_) tree_->adaptor.points = &points_;
  return *this;
}

std::pair<size_t, double> MapIndex::nearest(const Eigen::Vector2d& p) const {
  if (!tree_) return {SIZE_MAX, std::numeric_limits<double>::infinity()};
  uint32_t index = 0;
  double squared = 0;
  const double query[2] = {p.x(), p.y()};
  tree_->tree.knnSearch(query, 1, &index, &squared);
  return {size_t(index), std::sqrt(squared)};
}

// ---------------------------------------------------------------------------------------------------
// The SVD step

Transform2d fit_rigid_2d(const std::vector<Eigen::Vector2d>& src, const std::vector<Eigen::Vector2d>& dst,
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
  Transform2d t{0, 0, std::atan2(cross, dot)};  // a single pair: atan2(0, 0) = 0, translation only
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
  for (const auto& c : curbs) {
    const double d = map.nearest(result.t.apply(c)).second;
    if (d <= gate && weight(d) > 0) {
      ++inliers;
      sum_squared += d * d;
    }
  }
  result.inliers = inliers;
  result.rmse = inliers ? std::sqrt(sum_squared / double(inliers)) : 0.0;
  result.outlier_ratio = curbs.empty() ? 1.0 : 1.0 - double(inliers) / double(curbs.size());
}

template <class WeightFn>
IcpResult run_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Transform2d initial,
                  const IcpParams& params, WeightFn weight) {
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
    for (const auto& c : curbs) {
      const Eigen::Vector2d p = result.t.apply(c);
      const auto [index, d] = map.nearest(p);
      if (!(d <= params.max_correspondence)) continue;
      const double wi = weight(d);
      if (!(wi > 0)) continue;
      src.push_back(p);
      dst.push_back(map.points()[index]);
      w.push_back(wi);
    }
    if (src.empty()) break;  // nothing to pull on: keep the current transform
    // Eq. 9 minimised for fixed correspondences; the increment is applied on top of the current pose.
    const Transform2d delta = fit_rigid_2d(src, dst, &w);
    result.t = delta.compose(result.t);
    ++result.iterations;
    if (std::hypot(delta.x, delta.y) < params.convergence && std::abs(delta.theta) < params.convergence) break;
  }
  score(map, curbs, params.max_correspondence, weight, result);
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

IcpResult icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Transform2d initial,
              const IcpParams& params, double reject_distance) {
  // Eq. 12: a curb farther than reject_distance from the map is an outlier and takes no part in the fit.
  return run_icp(map, curbs, initial, params, [reject_distance](double d) { return d <= reject_distance ? 1.0 : 0.0; });
}

IcpResult m_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Transform2d initial,
                const MIcpParams& params) {
  const double b = params.biweight_b, scale = params.scale_m;
  // IRLS weight of Eq. 22: rho'(u)/u = (1 - (u/B)^2)^2 inside B, 0 outside (rho is flat there).
  return run_icp(map, curbs, initial, params.icp, [b, scale](double d) {
    const double u = d / scale;
    if (!(std::abs(u) < b)) return 0.0;
    const double v = 1.0 - (u / b) * (u / b);
    return v * v;
  });
}

// ---------------------------------------------------------------------------------------------------
// Probabilistic ICP

Transform2d fuse_hypotheses(const std::vector<IcpHypothesis>& hypotheses, double outlier_temperature) {
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
    s += w * std::sin(h.t.theta);
    c += w * std::cos(h.t.theta);
  }
  return {x / total, y / total, std::atan2(s, c)};
}

IcpResult probabilistic_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs,
                            Transform2d initial, const ProbabilisticIcpParams& params, std::mt19937_64& rng) {
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
  score(map, curbs, std::min(d_g, params.global.max_correspondence), [](double) { return 1.0; }, result);
  return result;
}

}  // namespace lidarloop
