#include "localizer/curb_layer.hpp"

#include <algorithm>
#include <cmath>

#include "common/points_kd_tree.hpp"

namespace lidarloop {

struct CurbLayer::Index : PointsKdTree {
  using PointsKdTree::PointsKdTree;
};

CurbLayer::CurbLayer(const CurbMap& map, double spacing) : map_(map) {
  for (const auto& line : map_.curbs)
    for (size_t i = 1; i < line.size(); ++i) {
      const Eigen::Vector2d d = line[i] - line[i - 1];
      const double length = d.norm();
      if (length == 0) continue;
      const int steps = std::max(1, int(std::ceil(length / spacing)));
      for (int k = 0; k < steps; ++k) {
        points_.push_back(line[i - 1] + d * (double(k) / steps));
        tangents_.push_back(d / length);
      }
      if (i + 1 == line.size()) {
        points_.push_back(line[i]);
        tangents_.push_back(d / length);
      }
    }
  index_ = std::make_unique<Index>(&points_);
}

CurbLayer CurbLayer::load(const std::string& geojson_path, double spacing) {
  return CurbLayer(read_curb_map(geojson_path), spacing);
}

CurbLayer::~CurbLayer() = default;
// The index reads the points through a pointer to the member vector: re-aim it after a move.
CurbLayer::CurbLayer(CurbLayer&& other) noexcept
    : map_(std::move(other.map_)),
      points_(std::move(other.points_)),
      tangents_(std::move(other.tangents_)),
      index_(std::move(other.index_)) {
  if (index_) index_->adaptor.points = &points_;
}
CurbLayer& CurbLayer::operator=(CurbLayer&& other) noexcept {
  map_ = std::move(other.map_);
  points_ = std::move(other.points_);
  tangents_ = std::move(other.tangents_);
  index_ = std::move(other.index_);
  if (index_) index_->adaptor.points = &points_;
  return *this;
}

std::vector<size_t> CurbLayer::window_indices(const Eigen::Vector2d& centre, double half_extent) const {
  std::vector<std::pair<uint32_t, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = false;
  const double radius = half_extent * std::sqrt(2.0);
  index_->tree.radiusSearch(centre.data(), radius * radius, matches, params);
  std::sort(matches.begin(), matches.end());  // deterministic order: by point index
  std::vector<size_t> out;
  for (const auto& [i, d2] : matches) {
    const Eigen::Vector2d& p = points_[i];
    if (std::abs(p.x() - centre.x()) <= half_extent && std::abs(p.y() - centre.y()) <= half_extent) out.push_back(i);
  }
  return out;
}

std::vector<Eigen::Vector2d> CurbLayer::window(const Eigen::Vector2d& centre, double half_extent) const {
  std::vector<Eigen::Vector2d> out;
  for (size_t i : window_indices(centre, half_extent)) out.push_back(points_[i]);
  return out;
}

double CurbLayer::distance(const Eigen::Vector2d& p) const {
  uint32_t index = 0;
  double d2 = 0;
  index_->tree.knnSearch(p.data(), 1, &index, &d2);
  return std::sqrt(d2);
}

}  // namespace lidarloop
