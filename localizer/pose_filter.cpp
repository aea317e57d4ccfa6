#include "localizer/pose_filter.hpp"
#include "common/units.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace lidarloop {

constexpr double kTyresPerAxle = 2;  // Eq. 19's factor 2: the stiffness is per tyre

Pose2d MotionPredictor::advance(Pose2d pose, double v, double delta, int64_t dt_ns, double max_step_s) {
  const int64_t max_step_ns = std::max<int64_t>(1, int64_t(max_step_s * kNsPerS));
  for (int64_t done = 0; done < dt_ns;) {
    const int64_t h = std::min(max_step_ns, dt_ns - done);
    pose = predict(pose, v, delta, double(h) / kNsPerS);  // Eq. 19 (Euler)
    done += h;
  }
  return pose;
}

Pose2d MotionPredictor::predict(const Pose2d& pose, double v, double delta, double dt) {
  const double L = p_.lf + p_.lr;
  v = std::max(0.0, v);
  if (v < p_.kinematic_below) {
    // Kinematic bicycle about the rear axle: no slip, yaw rate v tan(delta) / L.
    beta_ = std::atan(p_.lr * std::tan(delta) / L);
    yaw_rate_ = v * std::tan(delta) / L;
    lateral_acceleration_ = v * yaw_rate_;
  } else {
    // Eq. 19 (Euler): side slip beta and yaw rate at the centre of mass.
    const double cf = kTyresPerAxle * p_.cornering_stiffness_front, cr = kTyresPerAxle * p_.cornering_stiffness_rear;
    const double alpha_f = delta - beta_ - p_.lf * yaw_rate_ / v;
    const double alpha_r = -beta_ + p_.lr * yaw_rate_ / v;
    const double beta_dot = cf / (p_.mass * v) * alpha_f + cr / (p_.mass * v) * alpha_r - yaw_rate_;
    const double yaw_acc = (p_.lf * cf * alpha_f - p_.lr * cr * alpha_r) / p_.yaw_inertia;
    beta_ += beta_dot * dt;
    yaw_rate_ += yaw_acc * dt;
    lateral_acceleration_ = v * (yaw_rate_ + beta_dot);
  }
  // Lateral velocity of the rear axle in the body frame: none in the kinematic model; with Eq. 19's
  // slip, the centre of mass's v tan(beta) carried back to the axle: v tan(beta) - l_r psi_dot.
  const double lateral = v < p_.kinematic_below ? 0.0 : v * std::tan(beta_) - p_.lr * yaw_rate_;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  return {pose.x + (v * c - lateral * s) * dt, pose.y + (v * s + lateral * c) * dt,
          wrap_angle(pose.yaw + yaw_rate_ * dt)};
}

PoseFilter::PoseFilter(const Pose2d& initial, const Eigen::Matrix3d& covariance, const PoseFilterParams& params)
    : params_(params) {
  x_.head<3>() = Eigen::Vector3d(initial.x, initial.y, initial.yaw);
  P_.topLeftCorner<3, 3>() = covariance;
  start_mount_yaw();
}

PoseFilter PoseFilter::from_gps_fix(const Eigen::Vector3d& z, const GpsErrorModel& gps,
                                    const PoseFilterParams& params) {
  const Eigen::Matrix3d B = gps.bias_variance.asDiagonal();
  PoseFilter f({z.x(), z.y(), wrap_angle(z.z())}, B + Eigen::Matrix3d(gps.white_variance.asDiagonal()), params);
  f.gps_ = gps;
  f.P_.block<3, 3>(kBias, kBias) = B;
  f.P_.block<3, 3>(0, kBias) = -B;  // pose = z - bias - white
  f.P_.block<3, 3>(kBias, 0) = -B;
  return f;
}

void PoseFilter::start_mount_yaw() {
  // The heading was given as the car's; the matching heading is that plus the mount yaw (estimate 0).
  const double v = params_.mount_yaw_sigma_rad * params_.mount_yaw_sigma_rad;
  if (v == 0) return;
  P_(2, 2) += v;
  P_(2, kMount) = P_(kMount, 2) = v;
  P_(kMount, kMount) = v;
}

void PoseFilter::start_bias(const GpsErrorModel& gps) {
  x_.segment<3>(kBias).setZero();
  P_.block<3, 3>(kBias, kBias) = gps.bias_variance.asDiagonal();
  // Independent of everything else, a fresh start.
  P_.block<3, 3>(kBias, 0).setZero();
  P_.block<3, 3>(0, kBias).setZero();
  P_.block<1, 3>(kMount, kBias).setZero();
  P_.block<3, 1>(kBias, kMount).setZero();
}

Eigen::Matrix<double, 3, PoseFilter::kStates> PoseFilter::car_from_state() {
  Eigen::Matrix<double, 3, kStates> A = Eigen::Matrix<double, 3, kStates>::Zero();
  A.leftCols<3>().setIdentity();
  A(2, kMount) = -1;
  return A;
}

Eigen::Matrix3d PoseFilter::car_covariance() const {
  if (!learns_mount_yaw()) return covariance();
  const Eigen::Matrix<double, 3, kStates> A = car_from_state();
  return A * P_ * A.transpose();
}

void PoseFilter::reset_pose(const Pose2d& pose, const Eigen::Matrix3d& covariance, const UnplacedAxes& unplaced) {
  if (learns_mount_yaw())
    reset_states<kStates>(covariance, unplaced);
  else
    reset_states<kMount>(covariance, unplaced);
  x_.head<3>() = Eigen::Vector3d(pose.x, pose.y, pose.yaw);
}

template <int M>
void PoseFilter::reset_states(const Eigen::Matrix3d& covariance, const UnplacedAxes& unplaced) {
  using MatrixM = Eigen::Matrix<double, M, M>;
  // In a frame whose first axis is `along` (any, without it), for the pose and the bias alike.
  const Eigen::Vector2d u = unplaced.along.value_or(Eigen::Vector2d::UnitX()).normalized();
  Eigen::Matrix3d to_frame = Eigen::Matrix3d::Identity();
  to_frame.topLeftCorner<2, 2>() << u.x(), u.y(), -u.y(), u.x();
  MatrixM T = MatrixM::Identity();
  T.template topLeftCorner<3, 3>() = to_frame;
  T.template block<3, 3>(kBias, kBias) = to_frame;
  const MatrixM old = T * P_.topLeftCorner<M, M>() * T.transpose();
  MatrixM P = MatrixM::Zero();
  P.template topLeftCorner<3, 3>() = to_frame * covariance * to_frame.transpose();
  if (gps_) P.template block<3, 3>(kBias, kBias) = to_frame * gps_->bias_variance.asDiagonal() * to_frame.transpose();
  // Each unplaced axis keeps its block of the old covariance: along with its bias (0 and 3), the heading
  // with its bias and the mount yaw (2, 5 and 6), which no search places. A placed heading leaves the
  // mount yaw its own. The search's covariance says how the axes go together; blocks taken whole from a
  // covariance, side by side, are one.
  std::vector<std::vector<int>> kept;
  if (unplaced.along) kept.push_back({0, kBias});
  if (unplaced.heading) kept.push_back({2, kBias + 2});
  if (M > kMount) {
    if (unplaced.heading)
      kept.back().push_back(kMount);
    else
      kept.push_back({kMount});
  }
  for (const std::vector<int>& block : kept)
    for (int i : block)
      for (int j : block) P(i, j) = old(i, j);
  P_.topLeftCorner<M, M>() = T.transpose() * P * T;
}

void PoseFilter::predict(const Pose2d& predicted, double distance, double dt) {
  // Jacobian of moving by the odometry increment: a displacement (dx, dy) in the body frame rotates with
  // the car's heading, psi_m - mount yaw.
  const double dpx = predicted.x - x_(0), dpy = predicted.y - x_(1);
  const double turned_variance = params_.yaw_per_sqrt_rad > 0 ? params_.yaw_per_sqrt_rad * params_.yaw_per_sqrt_rad *
                                                                    std::abs(wrap_angle(predicted.yaw - car_pose().yaw))
                                                              : 0.0;
  Matrix F = Matrix::Identity();
  F(0, 2) = -dpy;
  F(1, 2) = dpx;
  F(0, kMount) = dpy;
  F(1, kMount) = -dpx;
  x_.head<3>() = Eigen::Vector3d(predicted.x, predicted.y, wrap_angle(predicted.yaw + x_(kMount)));
  auto sq = [](double v) { return v * v; };
  const double q_pos = sq(params_.position_per_sqrt_m) * distance + sq(params_.position_per_sqrt_s) * dt;
  const double q_yaw = sq(params_.yaw_per_sqrt_m) * distance + turned_variance;  // + 0 exactly without it
  Vector q = Vector::Zero();
  q.head<3>() = Eigen::Vector3d(q_pos, q_pos, q_yaw);
  if (gps_) {
    // The exact discretisation of the Gauss-Markov bias: it decays by phi and its stationary variance
    // is kept by a fresh (1 - phi^2) of it.
    for (int i = 0; i < 3; ++i) {
      const double phi = std::exp(-std::max(0.0, dt) / gps_->tau_s(i));
      x_(kBias + i) *= phi;
      F(kBias + i, kBias + i) = phi;
      q(kBias + i) = gps_->bias_variance(i) * (1 - phi * phi);
    }
  }
  if (learns_mount_yaw())
    propagate<kStates>(F, q);
  else
    propagate<kMount>(F, q);
}

template <int M>
void PoseFilter::propagate(const Matrix& F, const Vector& q) {
  const Eigen::Matrix<double, M, M> f = F.topLeftCorner<M, M>();
  Eigen::Matrix<double, M, M> P = P_.topLeftCorner<M, M>();
  P = f * P * f.transpose();
  P.diagonal() += q.head<M>();
  P_.topLeftCorner<M, M>() = P;
}

template <int N>
void PoseFilter::update(const Eigen::Matrix<double, N, 1>& innovation, const Eigen::Matrix<double, N, N>& R,
                        const Eigen::Matrix<double, N, kStates>& H) {
  if (learns_mount_yaw())
    correct<kStates, N>(innovation, R, H);
  else
    correct<kMount, N>(innovation, R, H.template leftCols<kMount>());
}

template <int M, int N>
void PoseFilter::correct(const Eigen::Matrix<double, N, 1>& innovation, const Eigen::Matrix<double, N, N>& R,
                         const Eigen::Matrix<double, N, M>& H) {
  Eigen::Matrix<double, M, M> P = P_.topLeftCorner<M, M>();
  const Eigen::Matrix<double, N, N> S = H * P * H.transpose() + R;
  const Eigen::Matrix<double, M, N> K = P * H.transpose() * S.inverse();
  x_.head<M>() += K * innovation;
  x_(2) = wrap_angle(x_(2));
  // Joseph form: stays symmetric and positive definite whatever the rounding.
  const Eigen::Matrix<double, M, M> I_KH = Eigen::Matrix<double, M, M>::Identity() - K * H;
  P = I_KH * P * I_KH.transpose() + K * R * K.transpose();
  P_.topLeftCorner<M, M>() = P;
}

template <int N>
void PoseFilter::update_pose(const Eigen::Matrix<double, N, 1>& z, const Eigen::Matrix<double, N, N>& R,
                             const Eigen::Matrix<double, N, 3>& H) {
  Eigen::Matrix<double, N, 1> innovation = z - H * x_.head<3>();
  if constexpr (N == 3) innovation(2) = wrap_angle(innovation(2));  // angles as angles
  Eigen::Matrix<double, N, kStates> H7 = Eigen::Matrix<double, N, kStates>::Zero();
  H7.template leftCols<3>() = H;  // a match measures the matching pose: the mount yaw is in psi_m already
  update<N>(innovation, R, H7);
}

// A fix measures the car (psi_m - mount yaw) plus the bias.
Eigen::Vector3d PoseFilter::gps_innovation(const Eigen::Vector3d& z) const {
  const Pose2d car = car_pose();
  Eigen::Vector3d innovation = z - Eigen::Vector3d(car.x, car.y, car.yaw) - x_.segment<3>(kBias);
  innovation(2) = wrap_angle(innovation(2));
  return innovation;
}

Eigen::Matrix3d PoseFilter::gps_innovation_covariance(const GpsErrorModel& gps) const {
  // H = [A I] with A the car's rows; an unstarted bias is the model's stationary one.
  const Eigen::Matrix<double, 3, kStates> A = car_from_state();
  const Eigen::Matrix3d car = car_covariance();
  const Eigen::Matrix3d B =
      gps_ ? Eigen::Matrix3d(P_.block<3, 3>(kBias, kBias)) : Eigen::Matrix3d(gps.bias_variance.asDiagonal());
  const Eigen::Matrix3d cross = !gps_                ? Eigen::Matrix3d::Zero()
                                : learns_mount_yaw() ? Eigen::Matrix3d(A * P_.block<kStates, 3>(0, kBias))
                                                     : Eigen::Matrix3d(P_.block<3, 3>(0, kBias));
  return car + B + cross + cross.transpose() + Eigen::Matrix3d(gps.white_variance.asDiagonal());
}

void PoseFilter::update_gps(const Eigen::Vector3d& z, const GpsErrorModel& gps) {
  if (!gps_) start_bias(gps);
  gps_ = gps;  // the receiver's word on its stationary error may change from fix to fix
  Eigen::Matrix<double, 3, kStates> H;
  H << car_from_state().leftCols<kBias>(), Eigen::Matrix3d::Identity(), car_from_state().rightCols<1>();
  update<3>(gps_innovation(z), gps.white_variance.asDiagonal().toDenseMatrix(), H);
}

void PoseFilter::update_curb(const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
  update_pose<3>(z, R, Eigen::Matrix3d::Identity());
}

Eigen::Matrix<double, 2, 3> intensity_observation_matrix(const Eigen::Vector2d& J) {
  Eigen::Matrix<double, 2, 3> H;
  H << 1, 0, -J.x(), 0, 1, -J.y();
  return H;
}

// z = p + J (psi_prior - psi), i.e. z - J psi_prior = H x: the innovation stays z - p_prior.
void PoseFilter::update_intensity(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& J) {
  update_pose<2>(z - J * x_(2), R, intensity_observation_matrix(J));
}

void PoseFilter::update_intensity_along(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& u,
                                        const Eigen::Vector2d& J) {
  const Eigen::Matrix<double, 1, 3> H = u.transpose() * intensity_observation_matrix(J);
  update_pose<1>(Eigen::Matrix<double, 1, 1>(u.dot(z - J * x_(2))), Eigen::Matrix<double, 1, 1>(u.dot(R * u)), H);
}

}  // namespace lidarloop
