#pragma once
// A nanoflann KD-tree over a vector of 2-D points it does not own: the index behind the world's road
// and curb lookups (sim), the curb layer's window queries and the curb matcher's nearest-neighbour
// queries (localizer). Include it only from .cpp files, so nanoflann stays out of every header.
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace lidarloop {

// nanoflann's dataset interface over the points.
struct PointsAdaptor {
  const std::vector<Eigen::Vector2d>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][int(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;  // let nanoflann compute the bounding box
  }
};

struct PointsKdTree {
  static constexpr int kLeafSize = 16;  // nanoflann's usual trade-off between tree depth and leaf scans

  // After the points move, point `adaptor.points` at their new place; the tree stays valid.
  PointsAdaptor adaptor;
  nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>, PointsAdaptor, 2> tree;

  explicit PointsKdTree(const std::vector<Eigen::Vector2d>* points)
      : adaptor{points}, tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {
    tree.buildIndex();
  }
};

}  // namespace lidarloop
