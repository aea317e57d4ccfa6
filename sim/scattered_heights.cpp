#include "sim/scattered_heights.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace lidarloop {

ScatteredHeights::ScatteredHeights(std::vector<Eigen::Vector2d> points, std::vector<double> z)
    : points_(std::move(points)), z_(std::move(z)), tree_(&points_) {}

double ScatteredHeights::operator()(const Eigen::Vector2d& p) const {
  std::array<uint32_t, kNeighbours + 1> idx{};
  std::array<double, kNeighbours + 1> d2{};
  const size_t found = points_.empty() ? 0 : tree_.tree.knnSearch(p.data(), kNeighbours + 1, idx.data(), d2.data());
  if (found == 0) return 0;
  if (d2[0] < 1e-12) return z_[idx[0]];
  const double radius = found == kNeighbours + 1 ? std::sqrt(d2[found - 1]) : std::numeric_limits<double>::infinity();
  double sw = 0, swz = 0;
  for (size_t k = 0; k < std::min(found, kNeighbours); ++k) {
    const double d = std::sqrt(d2[k]);
    const double w = std::isinf(radius) ? 1 / (d * d) : std::pow(std::max(0.0, radius - d) / (radius * d), 2);
    sw += w;
    swz += w * z_[idx[k]];
  }
  return sw > 0 ? swz / sw : z_[idx[0]];
}

}  // namespace lidarloop
