#pragma once
// Localization optimisation (paper 3.3): the pose predicted from CAN with the vehicle model (Eq. 19),
// corrected by the low-cost GPS (the paper's KF1) and by the map-matching observations of curbs
// (x, y, psi) and intensity (x, y) (its KF2).
//
// The paper runs KF1 and feeds its output to KF2 as the prior. With independent measurement noise
// that cascade equals one linear Kalman filter on [x, y, psi] updated in turn by each observation,
// which is what this class is; the two updates keep the paper's names.
#include <cstdint>

#include <Eigen/Core>

#include "common/vehicle_messages.hpp"

namespace lidarloop {

// What the localizer knows of the car: Table I and the steering ratio (a real car's datasheet).
struct VehicleModelParams {
  double cornering_stiffness_front = 45980, cornering_stiffness_rear = 45980;  // per tyre, N/rad
  double lf = 1.4, lr = 1.2, yaw_inertia = 6000, mass = 2300;
  double steering_ratio = 16.0;
  double kinematic_below = 1.5;  // m/s: Eq. 19 divides by v_x; below this the kinematic bicycle
};

// Eq. 19, integrated with Euler's method as in the paper, from the rear-axle speed and the front
// wheel angle. The rear-axle bracket uses l_r (the rear tyre's slip angle); the paper prints l_f.
class MotionPredictor {
 public:
  explicit MotionPredictor(const VehicleModelParams& params) : p_(params) {}
  // Advances the pose (rear axle, local frame) by dt with speed v and front wheel angle delta.
  Pose2d predict(const Pose2d& pose, double v, double delta, double dt);
  // The same over dt_ns, in Euler steps of at most max_step_s, v and delta held throughout.
  Pose2d advance(Pose2d pose, double v, double delta, int64_t dt_ns, double max_step_s);
  double yaw_rate() const { return yaw_rate_; }  // rad/s, as of the last step

 private:
  VehicleModelParams p_;
  double beta_ = 0, yaw_rate_ = 0;  // Eq. 19's dynamic states
};

// Process noise as random walks, so that it does not depend on how often predict() is called (CAN at
// 100 Hz or a gap of a second): variances grow linearly with the distance driven and the time passed.
struct PoseFilterParams {
  double position_per_sqrt_m = 0.05;  // m / sqrt(m): wheel slip, speed scale error, model error
  // rad / sqrt(m): steering offset, Eq. 19's simplifications. Set for a consistent heading over the scenario
  // suite (one value for all of it): 0.002 claimed twice the heading error there.
  double yaw_per_sqrt_m = 0.001;
  // m / sqrt(s): what odometry cannot see; also what lets the low-cost GPS's slowly wandering bias through,
  // so that with GPS alone the estimate follows the GPS within seconds rather than lagging it.
  double position_per_sqrt_s = 0.2;
};

// The intensity observation's H: z = p + J (psi_prior - psi) is linear in (x, y, psi) with rows
// [I, -J] (J: ApsResult::yaw_coupling; zero for a match that does not depend on the heading).
Eigen::Matrix<double, 2, 3> intensity_observation_matrix(const Eigen::Vector2d& J);

class PoseFilter {
 public:
  PoseFilter(const Pose2d& initial, const Eigen::Matrix3d& covariance, const PoseFilterParams& params = {});

  // Prediction: the pose moves to `predicted` (from MotionPredictor), having driven `distance` in `dt`.
  void predict(const Pose2d& predicted, double distance, double dt);
  // KF1: a GPS fix (x, y in the local frame, heading) with its covariance (3x3, x y psi).
  void update_gps(const Eigen::Vector3d& z, const Eigen::Matrix3d& R);
  // KF2: the curb matching observation (x_c, y_c, psi_c) and the intensity one (x_s, y_s).
  void update_curb(const Eigen::Vector3d& z, const Eigen::Matrix3d& R);
  // J: how the observation moves per radian of error in the heading it was made at (ApsResult's
  // yaw_coupling): z = p + J (psi_prior - psi), so the update corrects the heading too.
  void update_intensity(const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                        const Eigen::Vector2d& J = Eigen::Vector2d::Zero());
  // The intensity observation's component along the unit direction `u` only (z, R and J as above).
  void update_intensity_along(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& u,
                              const Eigen::Vector2d& J = Eigen::Vector2d::Zero());
  // Uncertainty the motion model does not know about (dead reckoning without CAN): P += Q.
  void inflate(const Eigen::Matrix3d& Q) { P_ += Q; }

  Pose2d pose() const { return {x_.x(), x_.y(), x_.z()}; }
  const Eigen::Matrix3d& covariance() const { return P_; }

 private:
  template <int N>
  void update(const Eigen::Matrix<double, N, 1>& z, const Eigen::Matrix<double, N, N>& R,
              const Eigen::Matrix<double, N, 3>& H);
  Eigen::Vector3d x_;  // x, y, psi
  Eigen::Matrix3d P_;
  PoseFilterParams params_;
};

}  // namespace lidarloop
