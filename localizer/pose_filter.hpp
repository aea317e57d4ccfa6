#pragma once
// Localization optimisation (paper 3.3): the pose predicted from CAN with the vehicle model (Eq. 19),
// corrected by the low-cost GPS (the paper's KF1) and by the map-matching observations of curbs
// (x, y, psi) and intensity (x, y) (its KF2).
//
// The paper runs KF1 and feeds its output to KF2 as the prior. With independent measurement noise
// that cascade equals one linear Kalman filter updated in turn by each observation, which is what this
// class is; the two updates keep the paper's names.
//
// Beyond the paper, the state carries the low-cost GPS's bias next to the pose: [x, y, psi, b_x, b_y,
// b_psi]. A low-cost receiver's error is mostly a bias that wanders over minutes (ionosphere,
// troposphere, multipath); taken as white noise, ten fixes a second would be counted as ten independent
// looks at the car and pull it to the bias within seconds. Carried as a first-order Gauss-Markov state
// (the standard GNSS error state: Groves, Principles of GNSS, Inertial, and Multisensor Integrated
// Navigation Systems, 2nd ed., 2013), the bias is learnt wherever the map pins the pose, and a fix
// then says only what its white noise allows. A GpsErrorModel without bias variance leaves the bias at
// zero: the paper's filter on [x, y, psi], each fix white noise (gps_noise.bias_state: false).
//
// Optionally the state also carries the LiDAR's mount yaw: how far the sensor is truly turned against
// the nominal mount the localizer places its points with (a calibration's residual, a fixed draw per
// car). Every map match then measures the heading of the nominal frame, psi + mount yaw, while CAN moves
// the car along psi and a GPS fix measures psi; so the filter's heading state is the matches' (psi_m,
// "the matching heading", in which the map is searched) and the car's is psi_m - mount yaw. What tells
// the mount apart is the motion: driven along psi_m, the car drifts across the road by the mount yaw
// times the distance, which the curbs see. The lever arm of the yaw (the sensor's offset ahead of the
// axle turned by it: 4 mm at 0.2 deg) is left out.
#include <cstdint>
#include <optional>

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
  // The centre of mass's lateral acceleration, v (yaw rate + d beta / dt), m/s^2 to the left, as of
  // the last step: into a bend the tyres' side force comes before the yaw rate has built up.
  double lateral_acceleration() const { return lateral_acceleration_; }

 private:
  VehicleModelParams p_;
  double beta_ = 0, yaw_rate_ = 0;  // Eq. 19's dynamic states
  double lateral_acceleration_ = 0;
};

// Process noise as random walks, so that it does not depend on how often predict() is called (CAN at
// 100 Hz or a gap of a second): variances grow linearly with the distance driven and the time passed.
struct PoseFilterParams {
  double position_per_sqrt_m = 0.05;  // m / sqrt(m): wheel slip, speed scale error, model error
  // rad / sqrt(m): steering offset, Eq. 19's simplifications. Set for a consistent heading over the scenario
  // suite (one value for all of it): 0.002 claimed twice the heading error there.
  double yaw_per_sqrt_m = 0.001;
  // rad / sqrt(rad) of heading turned: the yaw rate's scale error. Eq. 19 turns the car by the wheels'
  // speed, so a tyre radius off by 0.5 % (sim/can_model.hpp) or a steering ratio off by as much turns it
  // 0.5 % too far or short: 0.45 deg in a 90 deg bend, however long the bend. 0: none.
  double yaw_per_sqrt_rad = 0;
  // m / sqrt(s): what odometry cannot see; also what lets the low-cost GPS's slowly wandering bias through,
  // so that with GPS alone the estimate follows the GPS within seconds rather than lagging it.
  double position_per_sqrt_s = 0.2;
  // The LiDAR mount yaw's prior (rad, 1 sigma: the calibration's stated accuracy); 0: not a state.
  double mount_yaw_sigma_rad = 0;
};

// The low-cost GPS's error as the filter models it, per axis (x, y, psi): a Gauss-Markov bias of
// stationary variance `bias_variance` and correlation time `tau_s`, plus white noise.
struct GpsErrorModel {
  Eigen::Vector3d bias_variance = Eigen::Vector3d::Zero();
  Eigen::Vector3d white_variance = Eigen::Vector3d::Zero();
  Eigen::Vector3d tau_s = Eigen::Vector3d::Ones();
};

// The intensity observation's H: z = p + J (psi_prior - psi) is linear in (x, y, psi) with rows
// [I, -J] (J: ApsResult::yaw_coupling; zero for a match that does not depend on the heading).
Eigen::Matrix<double, 2, 3> intensity_observation_matrix(const Eigen::Vector2d& J);

// What a search that relocalizes the car did not place: the position along `along` (a unit direction),
// the heading.
struct UnplacedAxes {
  std::optional<Eigen::Vector2d> along;
  bool heading = false;
};

class PoseFilter {
 public:
  static constexpr int kStates = 7;  // x, y, psi_m, b_x, b_y, b_psi, mount yaw
  using Vector = Eigen::Matrix<double, kStates, 1>;
  using Matrix = Eigen::Matrix<double, kStates, kStates>;

  // The car's pose known from elsewhere (the caller): the GPS bias is unknown until the first fix.
  PoseFilter(const Pose2d& initial, const Eigen::Matrix3d& covariance, const PoseFilterParams& params = {});
  // A cold start from one fix z (x, y, psi): the car is where the fix says, as far off as the fix's
  // bias and white noise together, and whatever the bias turns out to be, the car is off by minus it.
  static PoseFilter from_gps_fix(const Eigen::Vector3d& z, const GpsErrorModel& gps,
                                 const PoseFilterParams& params = {});

  // Prediction: the car moves to `predicted` (car_pose() moved by MotionPredictor), having driven
  // `distance` in `dt`.
  void predict(const Pose2d& predicted, double distance, double dt);
  // KF1: a GPS fix (x, y in the local frame, heading): z = car_pose() + bias + white noise.
  void update_gps(const Eigen::Vector3d& z, const GpsErrorModel& gps);
  // The fix's innovation (z minus the car's pose and the bias, the angle wrapped) and its covariance: for
  // gating.
  Eigen::Vector3d gps_innovation(const Eigen::Vector3d& z) const;
  Eigen::Matrix3d gps_innovation_covariance(const GpsErrorModel& gps) const;
  // KF2: the curb matching observation (x_c, y_c, psi_c) and the intensity one (x_s, y_s), both of the
  // matching pose.
  void update_curb(const Eigen::Vector3d& z, const Eigen::Matrix3d& R);
  // J: how the observation moves per radian of error in the heading it was made at (ApsResult's
  // yaw_coupling): z = p + J (psi_prior - psi), so the update corrects the heading too.
  void update_intensity(const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                        const Eigen::Vector2d& J = Eigen::Vector2d::Zero());
  // The intensity observation's component along the unit direction `u` only (z, R and J as above).
  void update_intensity_along(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const Eigen::Vector2d& u,
                              const Eigen::Vector2d& J = Eigen::Vector2d::Zero());
  // Uncertainty the motion model does not know about (dead reckoning without CAN): P += Q on the pose.
  void inflate(const Eigen::Matrix3d& Q) { P_.topLeftCorner<3, 3>() += Q; }
  // The matching pose put elsewhere by a search (a relocalization). What the search placed has no tie to the
  // GPS bias, and the bias on that axis, whose estimate leant on the old pose, starts over from its
  // stationary doubt (its estimate is kept). What it did not place keeps the filter's doubt and its tie
  // to the bias: cutting that tie while keeping both doubts would let each next fix shrink both, and a
  // car lost for seconds would end up sure of a position along the road that no one had measured.
  void reset_pose(const Pose2d& pose, const Eigen::Matrix3d& covariance, const UnplacedAxes& unplaced = UnplacedAxes());
  // A fault injected from outside (a kidnap): the pose is moved, the filter none the wiser.
  void displace_to(const Pose2d& pose) { x_.head<3>() = Eigen::Vector3d(pose.x, pose.y, pose.yaw); }

  // The matching pose (psi_m: the heading the map matches measure) and its covariance; without a mount
  // yaw state, the car's.
  Pose2d pose() const { return {x_(0), x_(1), x_(2)}; }
  Eigen::Matrix3d covariance() const { return P_.topLeftCorner<3, 3>(); }
  // The car's pose (psi = psi_m - mount yaw) and its covariance.
  Pose2d car_pose() const { return {x_(0), x_(1), wrap_angle(x_(2) - x_(kMount))}; }
  Eigen::Matrix3d car_covariance() const;
  bool learns_mount_yaw() const { return params_.mount_yaw_sigma_rad > 0; }
  double mount_yaw() const { return x_(kMount); }  // rad, the true mount's against the nominal
  double mount_yaw_variance() const { return P_(kMount, kMount); }
  bool has_gps_bias() const { return gps_.has_value(); }  // a fix has come
  Eigen::Vector3d gps_bias() const { return x_.segment<3>(kBias); }
  Eigen::Matrix3d gps_bias_covariance() const { return P_.block<3, 3>(kBias, kBias); }

 private:
  static constexpr int kBias = 3, kMount = 6;
  // The car's pose from the state: [I 0 -e_psi].
  static Eigen::Matrix<double, 3, kStates> car_from_state();
  // The mount yaw's prior, tied to a matching heading that was set as the car's.
  void start_mount_yaw();
  // The Kalman filter's arithmetic runs on the states in use, the first M: without a mount yaw state the
  // first six, so that such a filter computes to the bit what it did before that state existed.
  template <int N>
  void update(const Eigen::Matrix<double, N, 1>& innovation, const Eigen::Matrix<double, N, N>& R,
              const Eigen::Matrix<double, N, kStates>& H);
  template <int M, int N>
  void correct(const Eigen::Matrix<double, N, 1>& innovation, const Eigen::Matrix<double, N, N>& R,
               const Eigen::Matrix<double, N, M>& H);
  template <int M>
  void propagate(const Matrix& F, const Vector& q);
  template <int M>
  void reset_states(const Eigen::Matrix3d& covariance, const UnplacedAxes& unplaced);
  template <int N>
  void update_pose(const Eigen::Matrix<double, N, 1>& z, const Eigen::Matrix<double, N, N>& R,
                   const Eigen::Matrix<double, N, 3>& H);
  // The bias's prior, the first time a fix arrives: stationary, independent of the pose.
  void start_bias(const GpsErrorModel& gps);
  Vector x_ = Vector::Zero();  // x, y, psi_m, b_x, b_y, b_psi, mount yaw
  Matrix P_ = Matrix::Zero();
  PoseFilterParams params_;
  std::optional<GpsErrorModel> gps_;  // the bias's model, once a fix has come
};

}  // namespace lidarloop
