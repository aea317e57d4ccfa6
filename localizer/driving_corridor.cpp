#include "localizer/driving_corridor.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace lidarloop {

Eigen::Vector2d world_to_vehicle(const Pose2d& pose, const Eigen::Vector2d& p_world) {
  // Rotate the offset by -yaw: the vehicle's heading becomes +x, its left +y.
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const double dx = p_world.x() - pose.x, dy = p_world.y() - pose.y;
  return {c * dx + s * dy, -s * dx + c * dy};
}

Eigen::Vector2d vehicle_to_world(const Pose2d& pose, const Eigen::Vector2d& p) {
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  return {pose.x + c * p.x() - s * p.y(), pose.y + s * p.x() + c * p.y()};
}

namespace {

// Cell of a vehicle-frame point, shared by the projection (Eq. 1) and the queries so both agree.
std::optional<cv::Point> cell_of(const CorridorParams& params, const Eigen::Vector2d& p) {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || params.cell_m <= 0) return std::nullopt;
  // floor, not truncation, so the cells either side of 0 are not merged into one double-size cell.
  const double col = std::floor(p.x() / params.cell_m) + params.width_cells / 2;
  const double row = std::floor(-p.y() / params.cell_m) + params.height_cells / 2;
  if (col < 0 || row < 0 || col >= params.width_cells || row >= params.height_cells) return std::nullopt;
  return cv::Point(static_cast<int>(col), static_cast<int>(row));
}

}  // namespace

std::optional<cv::Point> DrivingCorridor::cell(const Eigen::Vector2d& p_vehicle) const {
  return cell_of(params, p_vehicle);
}

bool DrivingCorridor::contains(const Eigen::Vector2d& p_vehicle) const {
  if (mask.empty()) return false;
  const auto c = cell(p_vehicle);
  return c && mask.at<std::uint8_t>(*c) != 0;
}

std::vector<size_t> DrivingCorridor::inside(const std::vector<Eigen::Vector3d>& points_vehicle) const {
  std::vector<size_t> out;
  if (mask.empty() || !(params.cell_m > 0)) return out;
  out.reserve(points_vehicle.size());
  for (size_t i = 0; i < points_vehicle.size(); ++i)
    if (const auto c = cell_of(params, points_vehicle[i].head<2>()); c && mask.at<std::uint8_t>(*c) != 0)
      out.push_back(i);
  return out;
}

DrivingCorridor extract_driving_corridor(const std::vector<Eigen::Vector2d>& curbs_world, const Pose2d& pose,
                                         const CorridorParams& params) {
  DrivingCorridor out{pose, params, cv::Mat()};
  if (params.width_cells <= 0 || params.height_cells <= 0 || !(params.cell_m > 0)) return out;

  // Eq. 1: G = 1 (255 here) where a curb falls in the cell, 0 otherwise.
  cv::Mat grid = cv::Mat::zeros(params.height_cells, params.width_cells, CV_8U);
  for (const auto& p : curbs_world) {
    if (const auto c = cell_of(params, world_to_vehicle(pose, p))) grid.at<std::uint8_t>(*c) = 255;
  }

  // Dilation: seal gaps and thin breaks in the curb lines (see CorridorParams::dilation_cells).
  if (params.dilation_cells > 0) {
    const int k = 2 * params.dilation_cells + 1;
    cv::dilate(grid, grid, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  }

  // The connected free region around the vehicle. Only that one component is wanted, so a flood fill
  // from the vehicle's cell does the work of labelling every component (and costs a third as much).
  // 4-connectivity: free space must not slip diagonally between two occupied cells that touch only
  // at a corner, which is exactly how a diagonal curb line is rasterised.
  cv::Mat free_space = grid == 0;  // 255 where free
  const cv::Point centre(params.width_cells / 2, params.height_cells / 2);
  cv::Point seed = centre;
  if (free_space.at<std::uint8_t>(centre) == 0) {
    // The vehicle's cell is a curb (or within the dilation radius of one): the pose is slightly off,
    // or the car really is next to the curb. Start from the nearest free cell; a full scan is cheap
    // next to the dilation and happens rarely.
    long best = std::numeric_limits<long>::max();
    for (int r = 0; r < free_space.rows; ++r) {
      const std::uint8_t* row = free_space.ptr<std::uint8_t>(r);
      for (int c = 0; c < free_space.cols; ++c) {
        if (row[c] == 0) continue;
        const long d2 =
            static_cast<long>(r - centre.y) * (r - centre.y) + static_cast<long>(c - centre.x) * (c - centre.x);
        if (d2 < best) best = d2, seed = {c, r};
      }
    }
    if (best == std::numeric_limits<long>::max()) return out;  // everything is occupied: no corridor
  }
  constexpr std::uint8_t kCorridor = 128;  // neither free (255) nor occupied (0)
  cv::floodFill(free_space, seed, cv::Scalar(kCorridor), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
  out.mask = free_space == kCorridor;  // CV_8U, 255 inside
  return out;
}

}  // namespace lidarloop
