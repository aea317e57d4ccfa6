#pragma once
// The map's curb points, indexed for the nearest-neighbour questions curb matching asks.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

// The map's curb points for nearest-neighbour queries. Keeps its own copy of the points, so it is safe
// to move and to build from a temporary.
//
// Two structures answer two kinds of question. nearest() has no bound and uses a KD-tree (nanoflann).
// ICP only ever wants the nearest point within a gate (d_g, the correspondence window), and asks
// thousands of times a scan: nearest_within() answers from square buckets, scanning rings of them
// outwards from the query's until nothing farther can be nearer. A curb map is lines of points 0.1 m
// apart, so a half-metre bucket holds five or so, and most answers (a curb matched within centimetres)
// come from three short runs of memory instead of a tree descent (benchmarks/bench_curb_matching.cpp
// measures both, and half a metre against one: 1.7 times faster at d_g; a quarter is slower again).
class MapIndex {
 public:
  static constexpr double kDefaultBucketM = 0.5;  // m: half the paper's d_g

  // What the index will be asked: a KD-tree for nearest() is built only for `any`. `within_only` indexes
  // thousands of points a scan (a parked car's returns) to ask nearest_within() up to bucket_m, where
  // building the tree cost more than all the questions.
  enum class Queries { any, within_only };
  explicit MapIndex(std::vector<Eigen::Vector2d> points, double bucket_m = kDefaultBucketM,
                    Queries queries = Queries::any);
  ~MapIndex();
  MapIndex(MapIndex&&) noexcept;
  MapIndex& operator=(MapIndex&&) noexcept;

  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  bool empty() const { return points_.empty(); }
  // Index of and Euclidean distance to the nearest map point; (SIZE_MAX, inf) for an empty map. Throws
  // std::logic_error for an index built `within_only`.
  std::pair<size_t, double> nearest(const Eigen::Vector2d& p) const;
  // The nearest map point if it is within `radius` (the same point nearest() finds, ties aside);
  // otherwise, or for a non-finite p, (SIZE_MAX, inf). An index built `within_only` throws
  // std::logic_error for a radius beyond four bucket sizes (of at least its bucket_m).
  std::pair<size_t, double> nearest_within(const Eigen::Vector2d& p, double radius) const;

 private:
  struct Tree;
  // Row-major buckets over the points' bounding box; the points re-ordered bucket by bucket, so the
  // buckets of one row of a query's neighbourhood are one contiguous run.
  struct Buckets {
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    double size = kDefaultBucketM;
    int cols = 0, rows = 0;
    std::vector<uint32_t> start;          // bucket k holds sorted[start[k] .. start[k + 1])
    std::vector<Eigen::Vector2d> sorted;  // the points in bucket order
    std::vector<uint32_t> index;          // sorted[i] is points_[index[i]]
  };
  std::vector<Eigen::Vector2d> points_;
  std::unique_ptr<Tree> tree_;
  Buckets buckets_;
};

}  // namespace lidarloop
