#include "loop/run_outputs.hpp"

#include <filesystem>
#include <limits>
#include <sstream>

#include "common/input_error.hpp"
#include "common/output_dir.hpp"
#include "localizer/driving_corridor.hpp"
#include "logs/ros2_messages.hpp"
#include "loop/fault_events.hpp"
#include "loop/localizer_setup.hpp"
#include "scoring/birdseye.hpp"
#include "scoring/error_plots.hpp"
#include "scoring/reference_trajectory.hpp"
#include "scoring/result_files.hpp"
#include "sim/sensor_calibration.hpp"

namespace lidarloop {
namespace {

void write_worst_frame(const std::string& path, const WorstFrame& w, const HdMap& map, const std::string& method) {
  if (w.error_m < 0) return;
  auto place = [&](const std::vector<Eigen::Vector2d>& vehicle_points) {
    std::vector<Eigen::Vector2d> world;
    for (const auto& p : vehicle_points) world.push_back(vehicle_to_world(w.estimate, p));
    return world;
  };
  BirdseyeOptions o;
  std::ostringstream title;
  title.precision(2);
  title << std::fixed << method << ": worst frame, position error " << w.error_m << " m";
  o.title = title.str();
  // `score` has no features (the localizer under test is not ours): no legend for what is not drawn.
  if (!w.features.curbs.empty())
    o.marks.push_back({"curb features (placed at the estimate)", place(w.features.curbs), {0, 0, 255}});
  if (!w.features.obstacles.empty())
    o.marks.push_back({"obstacle points (placed at the estimate)", place(w.features.obstacles), {255, 0, 255}});
  o.poses = {{"ground truth", w.truth, {255, 255, 255}}, {"estimate", w.estimate, {0, 200, 255}}};
  write_birdseye_png(path, w.cloud, w.sensor_pose, map.curbs.map().curbs, o);
}

}  // namespace

std::vector<TruthPose> truth_poses(const std::vector<TruthSample>& truth) {
  std::vector<TruthPose> out;
  out.reserve(truth.size());
  for (const auto& t : truth) out.push_back({t.stamp_ns, t.pose});
  return out;
}

std::vector<EstimateRecord> estimate_records(const std::vector<LocalizerEstimate>& estimates) {
  std::vector<EstimateRecord> out;
  out.reserve(estimates.size());
  for (size_t i = 0; i < estimates.size(); ++i) {
    const LocalizerEstimate& e = estimates[i];
    if (e.health & kNotInitialized) continue;
    out.push_back({e.stamp_ns,
                   {e.pose.x, e.pose.y, ros2::published_yaw(e.pose.yaw)},
                   e.covariance,
                   describe_health(e.health),
                   e.total_ms,
                   i == 0,
                   e.lost(),
                   e.protection_lateral_m,
                   e.protection_longitudinal_m,
                   e.mount_yaw ? e.mount_yaw->yaw_rad * kDegPerRad : std::numeric_limits<double>::quiet_NaN(),
                   e.mount_yaw ? e.mount_yaw->sigma_rad * kDegPerRad : std::numeric_limits<double>::quiet_NaN(),
                   e.fused_pose,
                   e.fused_intensity});
  }
  return out;
}

ScoredRun score_and_write(const std::string& dir, const std::string& scenario_name, const Scenario& scenario,
                          const Path& route, const std::vector<TruthPose>& truth, const std::string& method,
                          const std::vector<EstimateRecord>& estimates, const WorstFrame* worst, const HdMap& map,
                          const std::vector<CurbVisibility>& curb_visibility, const std::string& failure) {
  const std::vector<FaultEvent> events =
      truth.empty() ? std::vector<FaultEvent>{} : fault_events(scenario, truth.front().stamp_ns);
  // The reference, drawn from the truth and the seed here rather than in the simulation: the same in
  // `run`, `compare`, `replay` and `score`, and no stream of the drive changes with it.
  const bool with_reference = scenario.reference.kind != ReferenceConfig::Kind::none && !truth.empty();
  const std::vector<TruthPose> reference =
      with_reference ? reference_trajectory(truth, scenario.reference, scenario.seed) : std::vector<TruthPose>{};
  ScoredRun scored = score(truth, estimates, route, scenario.pass, method, scenario_name, events, curb_visibility,
                           scenario.lidar.scan_period_ns(), reference);
  if (scored.metrics.reference) scored.metrics.reference->config = scenario.reference;
  if (!failure.empty()) {
    scored.metrics.failures.push_back(failure);
    scored.metrics.pass = false;
  }
  scored.metrics.realism = realism_name(scenario.realism);
  scored.metrics.realism_overrides = realism_overrides(scenario);
  const MountDraw mount = draw_mount_error(scenario.mount_error, scenario.seed);  // as the simulation drew it
  scored.metrics.mount_error_rpy_deg = mount.lidar_rpy_rad * kDegPerRad;
  scored.metrics.mount_error_xyz_m = mount.lidar_xyz_m;
  // A third of what a target-based calibration achieves (0.1 deg; sim/sensor_calibration.hpp): learnt
  // to within that, the mount no longer shows in the heading beside the map's own 0.05 deg.
  constexpr double kMountYawToleranceDeg = 0.03;
  scored.metrics.mount_yaw =
      mount_yaw_metrics(estimates, scored.metrics.mount_error_rpy_deg.z(), kMountYawToleranceDeg);
  std::vector<MapObservation> poses, intensities;
  for (const EstimateRecord& e : estimates) {
    if (e.pose_observation) poses.push_back(*e.pose_observation);
    if (e.intensity_observation) intensities.push_back(*e.intensity_observation);
  }
  // An axis the curbs do not constrain (a straight's along, sigma of 100 m) says nothing to check: left
  // out beyond the inlier distance, beyond which the curb matcher takes no information either. APS's
  // axes are all checked: one it said nothing on is infinite already.
  if (!poses.empty())
    scored.metrics.pose_observations = observation_consistency(
        truth, poses, mount.lidar_rpy_rad.z(), localizer_params_for(scenario).curb_noise.inlier_distance_m);
  if (!intensities.empty())
    scored.metrics.intensity_observations =
        observation_consistency(truth, intensities, mount.lidar_rpy_rad.z(), std::numeric_limits<double>::infinity());

  prepare_output_dir(dir);
  write_metrics_json(dir + "/metrics.json", scored.metrics);
  write_errors_csv(dir + "/errors.csv", scored, estimates);
  write_tum(dir + "/estimate.tum", estimates);
  write_tum(dir + "/truth.tum", truth);
  if (with_reference)
    write_tum(dir + "/reference.tum", reference);
  else
    std::filesystem::remove(dir + "/reference.tum");  // an earlier run's in the same folder is not this run's
  write_junit(dir + "/junit.xml", {scored.metrics});
  write_error_plot(dir + "/errors.png", scored.errors, events);
  write_trajectory_plot(dir + "/trajectory.png", truth, estimates, scored.errors, map.curbs.map().curbs);
  if (worst) write_worst_frame(dir + "/worst_frame.png", *worst, map, method);
  return scored;
}

ScoredRun score_and_write(const std::string& dir, const std::string& scenario_name, const Scenario& scenario,
                          const Path& route, const std::vector<TruthSample>& truth, const std::string& method,
                          const std::vector<LocalizerEstimate>& estimates, const WorstFrame* worst, const HdMap& map,
                          const std::vector<CurbVisibility>& curb_visibility, const std::string& failure) {
  return score_and_write(dir, scenario_name, scenario, route, truth_poses(truth), method, estimate_records(estimates),
                         worst, map, curb_visibility, failure);
}

}  // namespace lidarloop
