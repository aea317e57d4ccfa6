// The `gicp` matcher's Open3D side (gicp_backend.hpp says why it is a module of its own): the map's
// target cloud with its GICP covariances, and Open3D's Generalized-ICP against it.
#include "localizer/gicp_backend.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <unordered_map>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GeneralizedICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/utility/Logging.h>
#include <Eigen/Dense>

namespace lidarloop {

namespace o3d = open3d::geometry;
namespace reg = open3d::pipelines::registration;

struct GicpCloud {
  o3d::PointCloud cloud;
};

namespace {

// Every OpenMP region inside runs on the calling thread: Open3D's sums and its gathering of
// correspondences then happen in one order, whatever the machine (see the header). The thread count
// is the calling thread's own OpenMP setting; it is restored on the way out.
class OneOpenMpThread {
 public:
  OneOpenMpThread() : saved_(omp_get_max_threads()) {
    omp_set_num_threads(1);
    // Open3D prints warnings (a cloud too small for its neighbours) on stdout, which would end up in
    // the command's output; our health flags say what went wrong instead.
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  }
  ~OneOpenMpThread() { omp_set_num_threads(saved_); }
  OneOpenMpThread(const OneOpenMpThread&) = delete;
  OneOpenMpThread& operator=(const OneOpenMpThread&) = delete;

 private:
  int saved_;
};

// The GICP paper's plane model (section III-B): each point's covariance from its k nearest neighbours
// (Open3D's KD-tree), made a plane: the eigenvector of its smallest eigenvalue is the surface normal n,
// and the covariance becomes the one with eigenvalues (epsilon, 1, 1) along (n, the plane), which is
// I - (1 - epsilon) n n^T. This is what Open3D itself does when it derives covariances from normals;
// we give them ready-made so it does not estimate normals (which Open3D runs on every core), and so
// the target can keep those of the points it had before. Only the points `which` are computed.
void set_plane_covariances(o3d::PointCloud& cloud, const std::vector<size_t>& which, const GicpParams& p) {
  cloud.covariances_.resize(cloud.points_.size(), Eigen::Matrix3d::Identity());
  if (which.empty()) return;
  const o3d::KDTreeFlann tree(cloud);
  std::vector<int> neighbours;
  std::vector<double> squared_distances;
  for (size_t i : which) {
    tree.SearchKNN(cloud.points_[i], p.covariance_neighbours, neighbours, squared_distances);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k : neighbours) mean += cloud.points_[size_t(k)];
    mean /= double(std::max<size_t>(neighbours.size(), 1));
    Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
    for (int k : neighbours) {
      const Eigen::Vector3d d = cloud.points_[size_t(k)] - mean;
      spread.noalias() += d * d.transpose();
    }
    const Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvectors().col(0);
    cloud.covariances_[i] = Eigen::Matrix3d::Identity() - (1.0 - p.epsilon) * n * n.transpose();
  }
}

void set_plane_covariances(o3d::PointCloud& cloud, const GicpParams& p) {
  std::vector<size_t> all(cloud.points_.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  set_plane_covariances(cloud, all, p);
}

// A map point by its exact coordinates (the same float of the same tile, whenever it is read).
struct ExactPointHash {
  size_t operator()(const Eigen::Vector3d& q) const {
    size_t h = 0;
    for (int k = 0; k < 3; ++k) h = h * 1000003u ^ std::hash<double>()(q[k]);
    return h;
  }
};

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// The covariance of (x, y, yaw) of the match. The GICP cost is sum_i d_i^T M_i^-1 d_i with
// M_i = C_target + R C_source R^T; its Gauss-Newton Hessian H = sum_i J_i^T M_i^-1 J_i (rotation
// about the vehicle's position, then translation) holds the geometry: along a featureless corridor
// it is small along the road, and the covariance below large there. The covariances M_i are shapes
// (eigenvalues epsilon, 1, 1), not metres, so H alone has no scale: the residuals give it, as the
// variance of a unit-weight residual, s^2 = sum_i d_i^T M_i^-1 d_i / (3 n - 6), and cov = s^2 H^-1
// (the usual least-squares estimate). It treats every correspondence as independent, which
// neighbouring points of one surface are not, so it is optimistic; we do not inflate it to taste.
// The map's own error is added by the caller.
Eigen::Matrix3d match_covariance(const o3d::PointCloud& source, const o3d::PointCloud& target,
                                 const reg::CorrespondenceSet& pairs, const Eigen::Vector3d& centre) {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  double r2 = 0;
  for (const Eigen::Vector2i& c : pairs) {
    const Eigen::Vector3d& q = source.points_[size_t(c[0])];
    const Eigen::Matrix3d M = target.covariances_[size_t(c[1])] + source.covariances_[size_t(c[0])];
    const Eigen::Matrix3d W = M.inverse();
    Eigen::Matrix<double, 3, 6> J;
    J << -skew(q - centre), Eigen::Matrix3d::Identity();
    H.noalias() += J.transpose() * W * J;
    const Eigen::Vector3d d = q - target.points_[size_t(c[1])];
    r2 += d.dot(W * d);
  }
  const double dof = std::max(1.0, 3.0 * double(pairs.size()) - 6.0);
  const Eigen::Matrix<double, 6, 6> cov = (r2 / dof) * H.inverse();
  // (x, y, yaw): translation x, y are 3 and 4, rotation about z is 2.
  constexpr int kIndex[3] = {3, 4, 2};
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = cov(kIndex[i], kIndex[j]);
  return out;
}

GicpCloud* build_cloud(const std::vector<Eigen::Vector3d>& map_points, const GicpCloud* previous,
                       const Eigen::Vector2d* previous_centre, double reuse_radius, const GicpParams& p) {
  const OneOpenMpThread one_thread;
  auto cloud = std::make_unique<GicpCloud>();
  cloud->cloud.points_.reserve(map_points.size());
  for (const Eigen::Vector3d& q : map_points)
    if (q.allFinite()) cloud->cloud.points_.push_back(q);
  std::vector<Eigen::Vector3d>& points = cloud->cloud.points_;
  if (points.size() > size_t(p.covariance_neighbours)) {
    // The previous target's covariances are kept for the points it shared with this one, except those
    // near its edge, whose neighbours it cut off (the neighbours of 0.4 m voxels lie within about 1 m):
    // at 10 m of reuse, two thirds of the points and of the time.
    std::unordered_map<Eigen::Vector3d, size_t, ExactPointHash> before;
    if (previous && previous_centre) {
      const std::vector<Eigen::Vector3d>& old = previous->cloud.points_;
      for (size_t i = 0; i < old.size(); ++i)
        if ((old[i].head<2>() - *previous_centre).squaredNorm() <= reuse_radius * reuse_radius)
          before.emplace(old[i], i);
    }
    cloud->cloud.covariances_.assign(points.size(), Eigen::Matrix3d::Identity());
    std::vector<size_t> fresh;
    for (size_t i = 0; i < points.size(); ++i)
      if (const auto it = before.find(points[i]); it != before.end())
        cloud->cloud.covariances_[i] = previous->cloud.covariances_[it->second];
      else
        fresh.push_back(i);
    set_plane_covariances(cloud->cloud, fresh, p);
  }
  return cloud.release();
}

void destroy_cloud(GicpCloud* cloud) { delete cloud; }

size_t cloud_size(const GicpCloud* cloud) { return cloud ? cloud->cloud.points_.size() : 0; }

GicpResult match(const std::vector<Eigen::Vector3d>& scan, const Eigen::Isometry3d& prior, const GicpCloud* target,
                 const GicpParams& p, double max_correspondence_m) {
  const OneOpenMpThread one_thread;
  GicpResult r;
  r.pose = prior;
  if (cloud_size(target) < size_t(std::max(p.min_map_points, p.covariance_neighbours + 1)) ||
      !target->cloud.HasCovariances()) {
    r.status = GicpStatus::few_map_points;
    return r;
  }
  o3d::PointCloud cropped;
  cropped.points_.reserve(scan.size());
  for (const Eigen::Vector3d& q : scan)
    if (q.allFinite() && q.norm() <= p.max_range_m && q.z() >= p.min_height_m) cropped.points_.push_back(q);
  const std::shared_ptr<o3d::PointCloud> source = cropped.VoxelDownSample(p.scan_voxel_m);
  r.scan_points = source->points_.size();
  if (r.scan_points < size_t(std::max(p.min_scan_points, p.covariance_neighbours + 1))) {
    r.status = GicpStatus::few_scan_points;
    return r;
  }
  set_plane_covariances(*source, p);

  const o3d::PointCloud& map = target->cloud;
  const reg::TransformationEstimationForGeneralizedICP estimation(p.epsilon);
  const reg::RegistrationResult result = reg::RegistrationGeneralizedICP(
      *source, map, max_correspondence_m, prior.matrix(), estimation,
      reg::ICPConvergenceCriteria(p.relative_fitness, p.relative_rmse, p.max_iterations));
  r.pose.matrix() = result.transformation_;
  r.fitness = result.fitness_;
  r.inlier_rmse = result.inlier_rmse_;
  r.correspondences = result.correspondence_set_.size();

  // The source where the match put it, with its covariances turned along (Open3D's Transform rotates
  // them): what the correspondences refer to.
  o3d::PointCloud placed = *source;
  placed.Transform(result.transformation_);
  if (r.correspondences < 6) {  // fewer than the unknowns: no match at all
    r.status = GicpStatus::low_fitness;
    return r;
  }
  const Eigen::Matrix4d step = estimation.ComputeTransformation(placed, map, result.correspondence_set_);
  const double step_angle = Eigen::AngleAxisd(Eigen::Matrix3d(step.topLeftCorner<3, 3>())).angle();
  if (!step.allFinite() || step.topRightCorner<3, 1>().norm() > p.converged_translation_m ||
      step_angle > p.converged_rotation_rad) {
    r.status = GicpStatus::not_converged;
    return r;
  }
  r.covariance = match_covariance(placed, map, result.correspondence_set_, r.pose.translation());
  r.covariance += Eigen::Vector3d(p.map_sigma_m * p.map_sigma_m, p.map_sigma_m * p.map_sigma_m,
                                  p.map_sigma_yaw_rad * p.map_sigma_yaw_rad)
                      .asDiagonal();
  if (!r.covariance.allFinite() || r.fitness < p.min_fitness) {
    r.status = GicpStatus::low_fitness;
    return r;
  }
  r.status = GicpStatus::ok;
  return r;
}

}  // namespace
}  // namespace lidarloop

extern "C" const lidarloop::GicpBackend* lidarloop_gicp_backend() {
  static const lidarloop::GicpBackend backend{lidarloop::build_cloud, lidarloop::destroy_cloud, lidarloop::cloud_size,
                                              lidarloop::match};
  return &backend;
}
