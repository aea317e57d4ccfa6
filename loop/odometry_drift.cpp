#include "loop/odometry_drift.hpp"

#include <algorithm>
#include <cmath>

#include "common/pose2d.hpp"
#include "common/units.hpp"
#include "localizer/localizer.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {

std::vector<OdometryDrift> odometry_drift(const std::vector<TruthSample>& truth, const std::vector<CanFrame>& can,
                                          const VehicleModelParams& vehicle, double max_step_s,
                                          const std::vector<double>& lengths_m) {
  std::vector<TruthPose> true_poses;
  for (const TruthSample& t : truth) true_poses.push_back({t.stamp_ns, t.pose});
  std::vector<OdometryDrift> out;
  for (double length : lengths_m) out.push_back({length, 0, 0, 0, 0});
  if (true_poses.size() < 2) return out;

  // The odometry at each frame's stamp, where the truth is known: the pose it has reached and the
  // distance the truth has driven by then.
  struct Sample {
    Pose2d odometry, truth;
    double distance;
  };
  std::vector<Sample> samples;
  MotionPredictor predictor(vehicle);
  Pose2d odometry;
  double speed = 0, steer = 0, distance = 0;
  std::optional<int64_t> last_ns;
  for (const CanFrame& f : can) {
    if (last_ns && f.stamp_ns < *last_ns) continue;
    const CanMotion m = can_motion(f, vehicle);
    if (!std::isfinite(m.speed) || !std::isfinite(m.steer)) continue;
    if (last_ns) odometry = predictor.advance(odometry, speed, steer, f.stamp_ns - *last_ns, max_step_s);
    speed = m.speed, steer = m.steer, last_ns = f.stamp_ns;
    if (f.stamp_ns < true_poses.front().stamp_ns || f.stamp_ns > true_poses.back().stamp_ns) continue;
    const Pose2d at = truth_at(true_poses, f.stamp_ns);
    if (!samples.empty()) distance += std::hypot(at.x - samples.back().truth.x, at.y - samples.back().truth.y);
    samples.push_back({odometry, at, distance});
  }

  for (OdometryDrift& d : out) {
    double lateral = 0, longitudinal = 0, heading = 0;
    size_t end = 0;
    double next_start = 0;
    for (size_t start = 0; start < samples.size(); ++start) {
      if (samples[start].distance < next_start) continue;
      while (next_start <= samples[start].distance) next_start += 1.0;  // a stretch every metre driven
      end = std::max(end, start);
      while (end < samples.size() && samples[end].distance - samples[start].distance < d.length_m) ++end;
      if (end == samples.size()) break;
      const Pose2d moved = relative(samples[start].odometry, samples[end].odometry);
      const Pose2d error = relative(samples[end].truth, samples[start].truth.compose(moved));  // in the truth's frame
      longitudinal += error.x * error.x, lateral += error.y * error.y, heading += error.yaw * error.yaw;
      ++d.stretches;
    }
    if (d.stretches == 0) continue;
    const double n = double(d.stretches);
    d.lateral_rms_m = std::sqrt(lateral / n);
    d.longitudinal_rms_m = std::sqrt(longitudinal / n);
    d.heading_rms_rad = std::sqrt(heading / n);
  }
  return out;
}

}  // namespace lidarloop
