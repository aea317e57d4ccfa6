#include "localizer/relocalization.hpp"

#include <cmath>
#include <limits>

#include "common/units.hpp"

namespace lidarloop {
namespace {

// A covariance given on the axes of `pose`'s vehicle frame (longitudinal, lateral, yaw), in the local frame.
Eigen::Matrix3d to_local(const Eigen::Vector3d& vehicle_variances, const Pose2d& pose) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(pose.yaw).toRotationMatrix();
  return R * vehicle_variances.asDiagonal() * R.transpose();
}

}  // namespace

Pose2d lateral_and_heading(const Pose2d& found, const Pose2d& prior) {
  const Pose2d d = relative(found, prior);  // the prior in found's vehicle frame
  return found.compose(Pose2d{d.x, 0, 0});
}

void Relocalizer::start(const Eigen::Vector3d& half_ranges, const std::vector<Hypothesis>& hypotheses,
                        const Pose2d& odometry) {
  carry(odometry);  // the pending place; the hypotheses are replaced below
  WideApsParams aps = p_.aps;
  aps.longitudinal_range_m = half_ranges.x();
  aps.lateral_range_m = half_ranges.y();
  aps.yaw_range_rad = half_ranges.z();
  CurbHypothesesParams curbs = p_.curbs;
  curbs.longitudinal_range_m = half_ranges.x();
  curbs.lateral_range_m = half_ranges.y();
  curbs.yaw_range_rad = half_ranges.z();
  aps_ = WideApsSearch(aps);
  curbs_ = CurbHypothesisSearch(curbs);
  // No hypothesis is sharper than the search can place a pose: a cell and a yaw step.
  hypotheses_ = hypotheses;
  const Eigen::Vector3d floor(p_.aps.aps.step_m, p_.aps.aps.step_m, p_.aps.fine_yaw_step_rad);
  for (Hypothesis& h : hypotheses_) h.sigmas = h.sigmas.cwiseMax(floor);
  active_ = true;
}

std::optional<Relocation> Relocalizer::step(IntensityGrid* S, IntensityMap& intensity,
                                            const std::vector<Eigen::Vector2d>& curbs, const MapIndex& curb_map,
                                            const Pose2d& prior, const Pose2d& odometry) {
  if (!active_) return std::nullopt;
  carry(odometry);  // the car drove on since the search started
  const bool have_curbs = curbs.size() >= size_t(p_.curbs.min_curbs) && !curb_map.points().empty();
  const bool curbs_now = have_curbs && (!S || curbs_turn_);
  curbs_turn_ = !curbs_turn_;
  std::optional<Relocation> found;
  if (curbs_now) {
    curbs_.step(curbs, curb_map, prior);
    if (curbs_.done()) {
      found = verdict(curbs_.result(), prior);
      curbs_.restart();
    }
  } else if (S) {
    S->pose = prior;
    aps_.step(*S, intensity);
    if (aps_.done()) {
      found = verdict(aps_.result(), prior);
      aps_.restart();
    }
  }
  return confirmed(found);
}

void Relocalizer::carry(const Pose2d& odometry) {
  const Pose2d moved = relative(odometry_, odometry);
  for (Hypothesis& h : hypotheses_) h.centre = h.centre.compose(moved);
  if (pending_) pending_ = pending_->compose(moved);
  odometry_ = odometry;
}

std::optional<Relocation> Relocalizer::confirmed(const std::optional<Relocation>& found) {
  if (!found || !found->longitudinal) return found;
  const bool again = pending_ &&
                     std::hypot(found->pose.x - pending_->x, found->pose.y - pending_->y) <= p_.confirm_distance_m &&
                     std::abs(wrap_angle(found->pose.yaw - pending_->yaw)) <= p_.confirm_yaw_deg / kDegPerRad;
  pending_ = found->pose;
  if (!again) return std::nullopt;
  pending_.reset();
  return found;
}

double Relocalizer::prior_term(const Pose2d& pose) const {
  double term = hypotheses_.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  for (const Hypothesis& h : hypotheses_) {
    const Pose2d d = relative(h.centre, pose);
    term = std::min(term, 0.5 * Eigen::Vector3d(d.x, d.y, d.yaw).cwiseQuotient(h.sigmas).squaredNorm());
  }
  return term;
}

std::optional<Relocation> Relocalizer::verdict(const WideApsResult& r, const Pose2d& prior) const {
  if (!r.ok || r.peak_on_edge || r.places.empty()) return std::nullopt;
  // Over the refinement's few cells the spread is cut short: at least a cell and a yaw step.
  Eigen::Matrix3d covariance = r.covariance;
  const Eigen::Vector3d floor(p_.aps.aps.step_m, p_.aps.aps.step_m, p_.aps.fine_yaw_step_rad);
  for (int i = 0; i < 3; ++i) covariance(i, i) = std::max(covariance(i, i), floor(i) * floor(i));
  // Each place with the prior (the posterior, in logs); the winner, and the best distinct other.
  auto posterior = [&](const WideApsResult::Place& place) { return place.log_p - prior_term(place.pose); };
  const WideApsResult::Place* winner = &r.places.front();
  for (const auto& place : r.places)
    if (posterior(place) > posterior(*winner)) winner = &place;
  const WideApsResult::Place* other = nullptr;
  for (const auto& place : r.places)
    if (std::hypot(place.pose.x - winner->pose.x, place.pose.y - winner->pose.y) > p_.aps.distinct_separation_m &&
        (!other || posterior(place) > posterior(*other)))
      other = &place;
  // A place none of the hypotheses allows is not taken, however well the paint fits there (a dashed
  // centre line alone fits as well either side of it).
  if (prior_term(winner->pose) > p_.max_prior_term) return std::nullopt;
  if (!other || posterior(*winner) - posterior(*other) >= p_.min_aps_margin)
    return Relocation{winner->pose, covariance, true};
  const Pose2d apart = relative(winner->pose, other->pose);
  if (std::abs(apart.y) > p_.along_road_lateral_m || std::abs(apart.yaw) > p_.along_road_yaw_deg / kDegPerRad)
    return std::nullopt;
  // Repeating paint along the road: the lateral position is fixed. So is the longitudinal one if the
  // prior alone makes the other place far less likely. APS's heading along a lone line is left alone:
  // over the refinement's small window its spread says too little of it.
  if (prior_term(other->pose) - prior_term(winner->pose) >= p_.min_prior_gap)
    return Relocation{winner->pose, covariance, true};
  Pose2d across = lateral_and_heading(winner->pose, prior);
  across.yaw = prior.yaw;
  return Relocation{across, covariance, false, false};
}

std::optional<Relocation> Relocalizer::verdict(const CurbHypothesesResult& r, const Pose2d& prior) const {
  if (!r.ok || r.best.score < p_.min_curb_score || r.ambiguous_lateral || r.ambiguous_yaw ||
      prior_term(r.best.pose) > p_.max_prior_term)
    return std::nullopt;
  // A place is a cluster of this radius: its spread, as a uniform one's sigma, on each axis.
  const double position = p_.curbs.cluster_radius_m / std::sqrt(3.0), yaw = p_.curbs.cluster_yaw_rad / std::sqrt(3.0);
  const Eigen::Matrix3d covariance =
      to_local(Eigen::Vector3d(position * position, position * position, yaw * yaw), r.best.pose);
  if (!r.ambiguous_longitudinal) return Relocation{r.best.pose, covariance, true};
  return Relocation{lateral_and_heading(r.best.pose, prior), covariance, false};
}

}  // namespace lidarloop
