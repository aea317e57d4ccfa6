#pragma once
// The `gicp` matcher's Open3D side is a module of its own (liblidarloop_gicp.so), loaded the first time
// a `gicp` target is built: Open3D links some 180 libraries, whose dynamic linking costs every process
// that loads them about a quarter of a second of CPU (`lidarloop --help` included), and only `gicp`
// needs them. gicp_matcher.cpp is the localizer's side; gicp_open3d.cpp the module's.
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "localizer/gicp_matcher.hpp"

namespace lidarloop {

struct GicpCloud;  // Open3D's cloud, with its GICP covariances

struct GicpBackend {
  // A target of the finite `map_points`; it keeps `previous`'s covariances of the points the two share
  // within `reuse_radius` of `previous_centre` (when both are given).
  GicpCloud* (*build)(const std::vector<Eigen::Vector3d>& map_points, const GicpCloud* previous,
                      const Eigen::Vector2d* previous_centre, double reuse_radius, const GicpParams& p);
  void (*destroy)(GicpCloud* cloud);
  size_t (*size)(const GicpCloud* cloud);  // 0 for none
  // gicp_match's contract, against `target` (which may be null: no map).
  GicpResult (*match)(const std::vector<Eigen::Vector3d>& scan, const Eigen::Isometry3d& prior, const GicpCloud* target,
                      const GicpParams& p, double max_correspondence_m);
};

// The module's one entry point.
extern "C" const GicpBackend* lidarloop_gicp_backend();

}  // namespace lidarloop
