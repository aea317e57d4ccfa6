#pragma once
// The sprung body's roll, predicted from CAN (beyond the paper). The LiDAR sits on the body, which in a
// bend rolls on its springs, outwards, about a pivot well above the ground: a scan put on the car with
// the mount alone then sees the road turned about that pivot, shifted sideways by about the roll times
// the pivot's height. At the 0.3 g of a campus bend a passenger car rolls 1.5 deg (5 deg/g), which moves
// the curbs and the paint 2 cm towards the bend's outside for a pivot 0.7 m up: as much as the curb
// match's own error, and the same way all through the bend.
//
// The ground plane the scan sees (2.1.2) cannot tell this roll from the road's crown and bank (the car
// sits on one half of a crowned road), so the roll is predicted from what causes it: the lateral
// acceleration, Eq. 19's from CAN's speed and steering (MotionPredictor::lateral_acceleration), through
// the body's roll mode q'' = -w^2 (q - K a_y / g) - 2 z w q' (the linear roll model of Gillespie,
// Fundamentals of Vehicle Dynamics, SAE 1992, ch. 8), with the car's roll gradient K, frequency and
// damping. Pitch under braking moves the road along by under a centimetre at 0.3 g (2 deg/g) and is left
// out; heave moves only heights, which the ground plane takes.
//
// One roll per scan, at the scan's reference time (its end), after the de-skew: entering a bend the
// roll changes 5-10 deg/s, so the scan's first firings are up to 1 deg off, about a centimetre sideways.
#include <vector>

#include <Eigen/Core>

namespace lidarloop {

struct BodyRollParams {
  bool enabled = true;
  // Gillespie ch. 8: passenger cars roll 3-7 deg/g; the middle of that range for Table I's 2300 kg car.
  double gradient_deg_per_g = 5.0;
  // Assumption: roll modes of passenger cars sit a little above bounce (1-1.5 Hz, Gillespie ch. 5).
  double frequency_hz = 1.5;
  double damping_ratio = 0.3;  // Gillespie ch. 5: passenger cars' damping ratios are 0.2-0.4
  // The height above the ground the body rolls about. A real body rolls about its roll axis, through
  // the suspensions' roll centres, which lie below the centre of mass (Gillespie ch. 8): a real car's
  // configuration gives that height here. The simulated car's body model rolls about its centre of
  // mass, and NHTSA rollover ratings give SUVs a static stability factor T / (2 h) of about 1.1-1.2:
  // with a 1.6 m track that is ~0.7 m up.
  double pivot_height_m = 0.7;
};

// The roll mode, stepped with the lateral acceleration.
class BodyRoll {
 public:
  explicit BodyRoll(const BodyRollParams& params) : p_(params) {}
  // Advances by dt seconds with lateral acceleration a_y (m/s^2, positive to the left) held. Beyond a
  // few settling times (a gap in CAN, a log's first message) the mode is at rest at its target.
  void step(double lateral_acceleration, double dt);
  // rad about the vehicle's x axis, positive = left side up (as in a left turn).
  double roll() const { return p_.enabled ? roll_ : 0.0; }

 private:
  BodyRollParams p_;
  double roll_ = 0, rate_ = 0;
};

// Points from the rolled body's frame to the vehicle frame (the ground plane under the wheels): turned
// by `roll` about the vehicle's x axis through the pivot at `pivot_height`.
void unroll(std::vector<Eigen::Vector3d>& points, double roll, double pivot_height);

}  // namespace lidarloop
