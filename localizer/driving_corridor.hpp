#pragma once
// Driving corridor extraction (paper section 2.1.1, Fig. 3): the curbs of the map around the vehicle
// are drawn into an occupancy grid G (Eq. 1), dilated to close gaps, and the free region connected to
// the vehicle is the corridor. Only LiDAR points inside it go on to obstacle rejection (2.1.2), so
// parked cars, pedestrians on the sidewalk and buildings never reach the ground fit.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/vehicle_messages.hpp"

namespace lidarloop {

// Table I: a 400 x 400 grid of 0.2 m cells, i.e. +-40 m around the vehicle.
struct CorridorParams {
  int width_cells = 400;   // w_g, cells along the vehicle's x (forward)
  int height_cells = 400;  // h_g, cells along the vehicle's y (left)
  double cell_m = 0.2;     // p_w = p_h
  // Radius of the dilation (cells; the structuring element is a (2r+1) square). It closes the gaps
  // between the map's curb points (0.1 m apart, so neighbouring cells, but rounding can still leave a
  // diagonal step) and thin breaks in the mapped curb (driveways drawn as a small gap, digitising
  // errors): up to 2r free cells between two curb cells are sealed, i.e. a break of about
  // (2r+1) cells = 1.0 m by default. The price: the corridor shrinks by r
  // cells (0.4 m by default) along every curb, and a road narrower than 2r+1 cells would be closed.
  int dilation_cells = 2;
};

struct DrivingCorridor {
  Pose2d pose;  // the vehicle pose (local frame) the grid was built around
  CorridorParams params;
  // CV_8U, 255 = corridor, 0 = curb, sidewalk or anything not connected to the vehicle. Laid out as
  // a bird's-eye image of the vehicle frame: column = forward (x grows to the right), row = left
  // (y grows upward, so row 0 is the leftmost strip); the vehicle sits at the centre cell
  // (row height/2, col width/2). Empty (no rows) if no corridor could be found.
  cv::Mat mask;

  // The grid cell of a vehicle-frame point (x forward, y left, m); nullopt outside the grid.
  std::optional<cv::Point> cell(const Eigen::Vector2d& p_vehicle) const;
  // True if the vehicle-frame point lies in a corridor cell. Points outside the grid are not in the
  // corridor: the grid is all the corridor we know of.
  bool contains(const Eigen::Vector2d& p_vehicle) const;
  // The indices of the points (vehicle frame; z is ignored) that contains() accepts, in order: a whole
  // scan at once, without a call per point (the corridor stage tests every point of the scan).
  std::vector<size_t> inside(const std::vector<Eigen::Vector3d>& points_vehicle) const;
};

// World (local map frame, x east y north) -> vehicle frame (x forward, y left) for `pose`.
Eigen::Vector2d world_to_vehicle(const Pose2d& pose, const Eigen::Vector2d& p_world);
// And back: a vehicle-frame point placed in the local frame by `pose`.
Eigen::Vector2d vehicle_to_world(const Pose2d& pose, const Eigen::Vector2d& p_vehicle);

// curbs_world: curb points in the local map frame (e.g. CurbLayer::window around the pose). Curbs
// outside the grid are ignored. With no curbs at all the whole grid is free, hence all corridor.
// If the vehicle's own cell is occupied (the pose is on or within r cells of a curb) the component
// of the nearest free cell is used; if every cell is occupied the mask is empty.
DrivingCorridor extract_driving_corridor(const std::vector<Eigen::Vector2d>& curbs_world, const Pose2d& pose,
                                         const CorridorParams& params = {});

}  // namespace lidarloop
