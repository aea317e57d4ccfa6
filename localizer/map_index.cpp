#include "localizer/map_index.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "common/points_kd_tree.hpp"

namespace lidarloop {

// The KD-tree, built by the first question that needs it: nearest_within answers from the buckets up
// to kMaxRings bucket sizes, which covers the gates the curb matchers ask, so most indexes (one a scan)
// are never asked and never pay for the tree, the larger part of building one. Questions may come from
// several threads at once (probabilistic_icp), hence the once_flag.
struct MapIndex::Tree {
  std::once_flag built;
  std::optional<PointsKdTree> kd;

  const PointsKdTree& get(const std::vector<Eigen::Vector2d>* points) {
    std::call_once(built, [&] { kd.emplace(points); });
    return *kd;
  }
  // After the points move: re-aim a tree already built (one built later reads them where they are).
  void points_moved(const std::vector<Eigen::Vector2d>* points) {
    if (kd) kd->adaptor.points = points;
  }
};

namespace {
// Beyond this many buckets per point (a small window of a large map is the usual case, but a caller
// may index a whole city), buckets grow instead: the answer stays exact, the memory bounded.
constexpr double kMaxBucketsPerPoint = 4.0;
constexpr double kMinBucketBudget = 4096;
// nearest_within scans rings of buckets up to this many bucket sizes out; beyond, it asks the tree.
constexpr double kMaxRings = 4;
}  // namespace

MapIndex::MapIndex(std::vector<Eigen::Vector2d> points, double bucket_m, Queries queries) : points_(std::move(points)) {
  if (!(bucket_m > 0) || !std::isfinite(bucket_m))
    throw std::invalid_argument("MapIndex: bucket size must be a positive number");
  for (const auto& p : points_)
    if (!p.allFinite()) throw std::invalid_argument("MapIndex: map points must be finite");
  // nanoflann cannot build over zero points; an empty map answers every query with "nothing".
  if (points_.empty()) return;
  if (queries == Queries::any) tree_ = std::make_unique<Tree>();  // built on demand

  Buckets& b = buckets_;
  Eigen::Vector2d lo = points_[0], hi = points_[0];
  for (const auto& p : points_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d extent = hi - lo;
  const double budget = std::max(kMinBucketBudget, kMaxBucketsPerPoint * double(points_.size()));
  b.size = std::max(bucket_m, std::sqrt((extent.x() + bucket_m) * (extent.y() + bucket_m) / budget));
  b.origin = lo;
  b.cols = int(extent.x() / b.size) + 1;
  b.rows = int(extent.y() / b.size) + 1;
  auto bucket_of = [&](const Eigen::Vector2d& p) {
    const int c = std::min(int((p.x() - lo.x()) / b.size), b.cols - 1);
    const int r = std::min(int((p.y() - lo.y()) / b.size), b.rows - 1);
    return size_t(r) * size_t(b.cols) + size_t(c);
  };
  // Counting sort by bucket, stable, so equal buckets keep the points' order.
  b.start.assign(size_t(b.cols) * size_t(b.rows) + 1, 0);
  for (const auto& p : points_) ++b.start[bucket_of(p) + 1];
  for (size_t k = 1; k < b.start.size(); ++k) b.start[k] += b.start[k - 1];
  std::vector<uint32_t> fill(b.start.begin(), b.start.end() - 1);
  b.sorted.resize(points_.size());
  b.index.resize(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) {
    const uint32_t slot = fill[bucket_of(points_[i])]++;
    b.sorted[slot] = points_[i];
    b.index[slot] = uint32_t(i);
  }
}
MapIndex::~MapIndex() = default;
// The tree reads the points through a pointer to the member vector: re-aim it after a move.
MapIndex::MapIndex(MapIndex&& other) noexcept
    : points_(std::move(other.points_)), tree_(std::move(other.tree_)), buckets_(std::move(other.buckets_)) {
  if (tree_) tree_->points_moved(&points_);
}
MapIndex& MapIndex::operator=(MapIndex&& other) noexcept {
  points_ = std::move(other.points_);
  tree_ = std::move(other.tree_);
  buckets_ = std::move(other.buckets_);
  if (tree_) tree_->points_moved(&points_);
  return *this;
}

std::pair<size_t, double> MapIndex::nearest(const Eigen::Vector2d& p) const {
  if (points_.empty()) return {SIZE_MAX, std::numeric_limits<double>::infinity()};
  if (!tree_) throw std::logic_error("MapIndex::nearest: the index was built for nearest_within only");
  uint32_t index = 0;
  double squared = 0;
  const double query[2] = {p.x(), p.y()};
  tree_->get(&points_).tree.knnSearch(query, 1, &index, &squared);
  return {size_t(index), std::sqrt(squared)};
}

std::pair<size_t, double> MapIndex::nearest_within(const Eigen::Vector2d& p, double radius) const {
  constexpr std::pair<size_t, double> none{SIZE_MAX, std::numeric_limits<double>::infinity()};
  if (points_.empty() || !p.allFinite() || !(radius >= 0)) return none;
  const Buckets& b = buckets_;
  const double rings = std::max(1.0, std::ceil(radius / b.size));
  if (rings > kMaxRings) {  // the circle spans many buckets: the tree is cheaper
    const auto found = nearest(p);
    return found.second <= radius ? found : none;
  }
  // The query's bucket, x and y divided as one pair (one vector division, each lane rounded as the
  // scalar one is).
  const Eigen::Array2d f = ((p - b.origin).array() / b.size).floor();
  const double fc = f.x(), fr = f.y();
  double best_squared = radius * radius;
  size_t best = SIZE_MAX;
  // Buckets r0..r1 x c0..c1, clamped to the grid in double first (so a query far off the map neither
  // overflows an int nor loops on doubles too large to step); each row's run is contiguous.
  auto scan = [&](double r0, double r1, double c0, double c1) {
    r0 = std::max(r0, 0.0);
    r1 = std::min(r1, double(b.rows - 1));
    c0 = std::max(c0, 0.0);
    c1 = std::min(c1, double(b.cols - 1));
    if (r0 > r1 || c0 > c1) return;
    for (int r = int(r0); r <= int(r1); ++r) {
      const size_t row = size_t(r) * size_t(b.cols);
      for (uint32_t i = b.start[row + size_t(c0)], end = b.start[row + size_t(c1) + 1]; i < end; ++i) {
        const double d = (b.sorted[i] - p).squaredNorm();
        if (d < best_squared || (d == best_squared && b.index[i] < best)) {
          best_squared = d;
          best = b.index[i];
        }
      }
    }
  };
  // The 3 x 3 buckets around p hold every point within one bucket size of it; ring k beyond them (the
  // buckets k away) every point within k sizes. A match mostly lies within centimetres of its curb, in
  // the first block, so the rings stop as soon as nothing farther can be nearer.
  scan(fr - 1, fr + 1, fc - 1, fc + 1);
  for (int k = 2; k <= int(rings) && best_squared > double((k - 1) * (k - 1)) * b.size * b.size; ++k) {
    scan(fr - k, fr - k, fc - k, fc + k);
    scan(fr + k, fr + k, fc - k, fc + k);
    scan(fr - k + 1, fr + k - 1, fc - k, fc - k);
    scan(fr - k + 1, fr + k - 1, fc + k, fc + k);
  }
  return best == SIZE_MAX ? none : std::pair<size_t, double>{best, std::sqrt(best_squared)};
}

}  // namespace lidarloop
