#include "localizer/pose_filter.hpp"
#include "common/units.hpp"

#include <algorithm>
#include <cmath>

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
  } else {
    // Eq. 19 (Euler): side slip beta and yaw rate at the centre of mass.
    const double cf = kTyresPerAxle * p_.cornering_stiffness_front, cr = kTyresPerAxle * p_.cornering_stiffness_rear;
    const double alpha_f = delta - beta_ - p_.lf * yaw_rate_ / v;
    const double alpha_r = -beta_ + p_.lr * yaw_rate_ / v;
    const double beta_dot = cf / (p_.mass * v) * alpha_f + cr / (p_.mass * v) * alpha_r - yaw_rate_;
    const double yaw_acc = (p_.lf * cf * alpha_f - p_.lr * cr * alpha_r) / p_.yaw_inertia;
    beta_ += beta_dot * dt;
    yaw_rate_ += yaw_acc * dt;
  }
  // Lateral velocity of the rear axle in the body frame: none in the kinematic model; with Eq. 19's
  // slip, the centre of mass's v tan(beta) carried back to the axle: v tan(beta) - l_r psi_dot.
  const double lateral = v < p_.kinematic_below ? 0.0 : v * std::tan(beta_) - p_.lr * yaw_rate_;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  return {pose.x + (v * c - lateral * s) * dt, pose.y + (v * s + lateral * c) * dt,
          wrap_angle(pose.yaw + yaw_rate_ * dt)};
}

PoseFilter::PoseFilter(const Pose2d& initial, const Eigen::Matrix3d& covariance, const PoseFilterParams& params)
    : x_(initial.x, initial.y, initial.yaw), P_(covariance), params_(params) {}

void PoseFilter::predict(const Pose2d& predicted, double distance, double dt) {
  // Jacobian of moving by the odometry increment: a displacement (dx, dy) in the body frame rotates with psi.
  const double dpx = predicted.x - x_.x(), dpy = predicted.y - x_.y();
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 2) = -dpy;
  F(1, 2) = dpx;
  x_ = Eigen::Vector3d(predicted.x, predicted.y, predicted.yaw);
  auto sq = [](double v) { return v * v; };
  const double q_pos = sq(params_.position_per_sqrt_m) * distance + sq(params_.position_per_sqrt_s) * dt;
  const double q_yaw = sq(params_.yaw_per_sqrt_m) * distance;
  const Eigen::Matrix3d Q = Eigen::Vector3d(q_pos, q_pos, q_yaw).asDiagonal();
  P_ = F * P_ * F.transpose() + Q;
}

template <int N>
void PoseFilter::update(const Eigen::Matrix<double, N, 1>& z, const Eigen::Matrix<double, N, N>& R,
                        const Eigen::Matrix<double, N, 3>& H) {
  Eigen::Matrix<double, N, 1> innovation = z - H * x_;
  if constexpr (N == 3) innovation(2) = wrap_angle(innovation(2));  // angles as angles
  const Eigen::Matrix<double, N, N> S = H * P_ * H.transpose() + R;
  const Eigen::Matrix<double, 3, N> K = P_ * H.transpose() * S.inverse();
  x_ += K * innovation;
  x_(2) = wrap_angle(x_(2));
  // Joseph form: stays symmetric and positive definite whatever the rounding.
  const Eigen::Matrix3d I_KH = Eigen::Matrix3d::Identity() - K * H;
  P_ = I_KH * P_ * I_KH.transpose() + K * R * K.transpose();
}

void PoseFilter::update_gps(const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
  update<3>(z, R, Eigen::Matrix3d::Identity());
}

void PoseFilter::update_curb(const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
  update<3>(z, R, Eigen::Matrix3d::Identity());
}

Eigen::Matrix<double, 2, 3> intensity_observation_matrix(const Eigen::Vector2d& J) {
  Eigen::Matrix<double, 2, 3> H;
  H << 1, 0, -J.x(), 0, 1, -J.y();
  return H;
}

// z = p + J (psi_prior - psi), i.e. z - J psi_prior = H x: the innovation stays z - p_prior.
void PoseFilter::update_intensity(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& J) {
  update<2>(z - J * x_.z(), R, intensity_observation_matrix(J));
}

void PoseFilter::update_intensity_along(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& u,
                                        const Eigen::Vector2d& J) {
  const Eigen::Matrix<double, 1, 3> H = u.transpose() * intensity_observation_matrix(J);
  update<1>(Eigen::Matrix<double, 1, 1>(u.dot(z - J * x_.z())), Eigen::Matrix<double, 1, 1>(u.dot(R * u)), H);
}

}  // namespace lidarloop
