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

void Relocalizer::start(const Eigen::Vector3d& half_ranges, const Eigen::Vector3d& prior_sigmas) {
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
  prior_sigmas_ = prior_sigmas;
  active_ = true;
}

std::optional<Relocation> Relocalizer::step(IntensityGrid* S, IntensityMap& intensity,
                                            const std::vector<Eigen::Vector2d>& curbs, const MapIndex& curb_map,
                                            const Pose2d& prior) {
  if (!active_) return std::nullopt;
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
  return found;
}

std::optional<Relocation> Relocalizer::verdict(const WideApsResult& r, const Pose2d& prior) const {
  if (!r.ok || r.peak_on_edge) return std::nullopt;
  // Eq. 14 with the prior: each place's log probability less half its squared distance from the prior
  // in the prior's sigmas.
  auto prior_term = [&](const Pose2d& pose) {
    const Pose2d d = relative(prior, pose);
    return 0.5 * Eigen::Vector3d(d.x, d.y, d.yaw).cwiseQuotient(prior_sigmas_).squaredNorm();
  };
  const double margin = std::isfinite(r.margin) ? r.margin + prior_term(r.runner_up) - prior_term(r.pose)
                                                : std::numeric_limits<double>::infinity();
  // Over the refinement's few cells the spread is cut short: at least a cell and a yaw step.
  Eigen::Matrix3d covariance = r.covariance;
  const Eigen::Vector3d floor(p_.aps.aps.step_m, p_.aps.aps.step_m, p_.aps.fine_yaw_step_rad);
  for (int i = 0; i < 3; ++i) covariance(i, i) = std::max(covariance(i, i), floor(i) * floor(i));
  if (margin >= p_.min_aps_margin) return Relocation{r.pose, covariance, true};
  const Pose2d other = relative(r.pose, r.runner_up);
  if (std::abs(other.y) <= p_.along_road_lateral_m && std::abs(other.yaw) <= p_.along_road_yaw_deg / kDegPerRad) {
    // Repeating paint along the road: the lateral position and the heading are fixed. So is the
    // longitudinal one if the other place is, by the prior alone, far less likely than the best.
    const bool prior_decides = prior_term(r.runner_up) - prior_term(r.pose) >= p_.min_prior_gap;
    return Relocation{prior_decides ? r.pose : lateral_and_heading(r.pose, prior), covariance, prior_decides};
  }
  return std::nullopt;
}

std::optional<Relocation> Relocalizer::verdict(const CurbHypothesesResult& r, const Pose2d& prior) const {
  if (!r.ok || r.best.score < p_.min_curb_score || r.ambiguous_lateral || r.ambiguous_yaw) return std::nullopt;
  // A place is a cluster of this radius: its spread, as a uniform one's sigma, on each axis.
  const double position = p_.curbs.cluster_radius_m / std::sqrt(3.0), yaw = p_.curbs.cluster_yaw_rad / std::sqrt(3.0);
  const Eigen::Matrix3d covariance =
      to_local(Eigen::Vector3d(position * position, position * position, yaw * yaw), r.best.pose);
  if (!r.ambiguous_longitudinal) return Relocation{r.best.pose, covariance, true};
  return Relocation{lateral_and_heading(r.best.pose, prior), covariance, false};
}

}  // namespace lidarloop
