#pragma once
// The `gicp` method's matcher (beyond the paper: a modern dense scan-to-map peer of the curb and paint
// matchers): Generalized-ICP (Segal, Haehnel & Thrun, RSS 2009) of the de-skewed scan, voxel-
// downsampled, against the map's point-cloud layer around the prior, by Open3D 0.16.1 (Debian
// libopen3d-dev 0.16.1+ds-2): open3d::pipelines::registration::RegistrationGeneralizedICP. Not a GICP
// of our own: we give Open3D the two clouds with their GICP covariances, an initial guess and its
// convergence criteria, and read back its transform and correspondences.
//
// Every parameter is in GicpParams (YAML `localizer: gicp:`), with why it has its default.
//
// Open3D's headers are heavy (seconds of compile per file that includes them) and its libraries slow
// every process's start: only gicp_open3d.cpp includes them, in a module loaded on first use
// (gicp_backend.hpp); the target below hides its cloud behind a pointer.
//
// Determinism: Open3D's registration sums over correspondences in OpenMP reductions and gathers them
// under a critical section, so its result depends on the thread count and on the threads' order.
// gicp_match and GicpTarget::build run every OpenMP region on the calling thread (the OpenMP thread
// count is set to 1 for the call and restored after), so the same inputs give the same bits.
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lidarloop {

struct GicpParams {
  // The scan's voxel size, m. Coarser than the map's (0.4 m): GICP needs a dense target for good
  // local planes, while the source's points only need to sample every surface; at 1 m a scan keeps
  // a few thousand points, and the iterations' nearest-neighbour searches, which cost most, scale with
  // them.
  double scan_voxel_m = 1.0;
  // Scan points farther than this from the vehicle are dropped: the mapping drive keeps returns up
  // to 40 m from the survey car (MappingOptions::max_range), so farther ones rarely have a partner.
  double max_range_m = 40.0;
  // Scan points lower than this below the vehicle frame's origin (the ground under the rear axle) are
  // dropped: none are real on this map (noise, multipath).
  double min_height_m = -3.0;
  // Neighbours of each point whose spread gives its covariance (the GICP paper's and Open3D's 20).
  int covariance_neighbours = 20;
  // The GICP paper's plane model: each covariance's eigenvalues become (epsilon, 1, 1), the surface
  // normal the small one (Open3D's default epsilon, 1e-3).
  double epsilon = 1e-3;
  // Correspondences farther apart than this are ignored, m. Twice the map's voxel: a point on a surface
  // is within half a voxel diagonal of the map's centroid of that surface, plus the prior's error.
  double max_correspondence_m = 1.0;
  // While the prior is uncertain (a first GPS fix), widened to this many sigmas of its position, up to
  // max_correspondence_widened_m, so a start metres off still converges.
  double window_sigmas = 3.0;
  double max_correspondence_widened_m = 3.0;
  // Open3D's ICPConvergenceCriteria: stop when fitness and inlier RMSE change by less than these
  // between iterations, or after max_iterations (Open3D's defaults: 1e-6, 1e-6, 30).
  double relative_fitness = 1e-6;
  double relative_rmse = 1e-6;
  int max_iterations = 30;
  // After the last iteration, one more GICP step (Open3D's estimation on the final correspondences)
  // must move the pose by less than this, or the match has not converged (Open3D 0.16 does not say).
  double converged_translation_m = 0.01;
  double converged_rotation_rad = 0.001;
  // The local target: map points within max_range_m + target_reuse_m + max_correspondence_widened_m
  // of the prior, kept (with covariances) until the prior moves target_reuse_m from where it was
  // cut, so the target is cut about once a second at 10 m/s, not every scan (and then keeps the
  // covariances of the points it shares with the last one).
  double target_reuse_m = 10.0;
  // A new target keeps the old one's covariances of the points they share, but for those within this
  // of the old one's edge (their neighbours were cut off there): 2 m, twice the reach of 20 neighbours.
  double covariance_reuse_margin_m = 2.0;
  // Health: fewer scan points after downsampling, or fewer map points in the target, and there is no
  // match; a match with a smaller fraction of scan points within max correspondence of the map
  // (Open3D's fitness) is refused: the scan is then mostly what the map does not know (traffic, a
  // changed world) or the match is off.
  int min_scan_points = 200;
  int min_map_points = 1000;
  double min_fitness = 0.5;
  // What no number of scan points can make better: the map itself is off by the survey's pose error
  // (mapping/survey_error.hpp: RTK-INS, 2 cm and 0.05 deg RMS), added to the match's own covariance.
  double map_sigma_m = 0.02;
  double map_sigma_yaw_rad = 0.05 * 3.14159265358979323846 / 180;
};

// The map points around the prior with their GICP covariances, built once and reused while the car
// stays near where it was cut.
class GicpTarget {
 public:
  GicpTarget();
  ~GicpTarget();
  GicpTarget(GicpTarget&&) noexcept;
  GicpTarget& operator=(GicpTarget&&) noexcept;

  // How far from the prior the target must reach.
  static double radius(const GicpParams& p);
  // True if a target was built within target_reuse_m of `centre`.
  bool covers(const Eigen::Vector2d& centre, const GicpParams& p) const;
  // Points of the map (local frame) around `centre`; non-finite points are dropped.
  void build(const std::vector<Eigen::Vector3d>& map_points, const Eigen::Vector2d& centre, const GicpParams& p);
  size_t size() const;
  size_t builds() const { return builds_; }

  struct Cloud;  // Open3D's, with covariances
  const Cloud* cloud() const { return cloud_.get(); }

 private:
  std::unique_ptr<Cloud> cloud_;
  std::optional<Eigen::Vector2d> centre_;
  size_t builds_ = 0;
};

// Whether this build has the gicp method: its Open3D module is built unless configured with
// -DLIDARLOOP_GICP=OFF, which `tools/quickstart.sh run` does where libopen3d-dev is not installed.
bool gicp_available();
// What to tell a user who asks for gicp where it is not available.
inline constexpr const char* kGicpUnavailable =
    "gicp: this lidarloop was built without Open3D (-DLIDARLOOP_GICP=OFF, as `tools/quickstart.sh run` builds it "
    "where libopen3d-dev is not installed); `tools/quickstart.sh test` installs it and builds the method";

enum class GicpStatus { ok, few_scan_points, few_map_points, not_converged, low_fitness };
const char* gicp_status_name(GicpStatus s);

struct GicpResult {
  GicpStatus status = GicpStatus::few_map_points;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // the vehicle in the map's local frame (6-DoF)
  // Of (x, y, yaw) of `pose`: the match's own (GICP Hessian scaled by its residuals) plus the map's.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double fitness = 0, inlier_rmse = 0;
  size_t scan_points = 0, correspondences = 0;

  bool ok() const { return status == GicpStatus::ok; }
};

// Registers `scan` (vehicle frame, de-skewed) against `target`, starting from `prior` (the vehicle
// in the local frame), with correspondences up to `max_correspondence_m`.
GicpResult gicp_match(const std::vector<Eigen::Vector3d>& scan, const Eigen::Isometry3d& prior,
                      const GicpTarget& target, const GicpParams& p, double max_correspondence_m);

}  // namespace lidarloop
