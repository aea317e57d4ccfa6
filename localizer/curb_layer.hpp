#pragma once
// The curb layer of the HD map (the paper's Fig. 9a): the curb map's lines in local metres, densified
// to points at most `spacing` apart, in a KD-tree for the nearest-curb and window queries that the
// corridor extraction and curb matching need.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/curb_map_file.hpp"

namespace lidarloop {

class CurbLayer {
 public:
  static constexpr double kDefaultSpacing = 0.1;  // m

  explicit CurbLayer(const CurbMap& map, double spacing = kDefaultSpacing);
  static CurbLayer load(const std::string& geojson_path, double spacing = kDefaultSpacing);
  ~CurbLayer();
  CurbLayer(CurbLayer&&) noexcept;
  CurbLayer& operator=(CurbLayer&&) noexcept;

  const CurbMap& map() const { return map_; }
  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  // Unit direction of the curb line at each point (of the segment it was sampled from): what a
  // point-to-line residual needs to know which way a curb constrains the pose.
  const std::vector<Eigen::Vector2d>& tangents() const { return tangents_; }

  // Curb points inside the axis-aligned square of half size `half_extent` around `centre`.
  std::vector<Eigen::Vector2d> window(const Eigen::Vector2d& centre, double half_extent) const;
  // The same window as indices into points() and tangents(), in increasing order.
  std::vector<size_t> window_indices(const Eigen::Vector2d& centre, double half_extent) const;
  // Distance from p to the nearest curb point (at most spacing/2 more than to the curb line).
  double distance(const Eigen::Vector2d& p) const;

 private:
  struct Index;
  CurbMap map_;
  std::vector<Eigen::Vector2d> points_, tangents_;
  std::unique_ptr<Index> index_;
};

}  // namespace lidarloop
