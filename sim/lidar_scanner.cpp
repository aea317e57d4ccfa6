#include "sim/lidar_scanner.hpp"
#include "common/units.hpp"

#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lidarloop {

namespace {
// Streams of the sensor-fault and weather draws, apart from the return model's (whose draws stay those
// of the sensor before these were modelled, so a dry day with every fault off gives the same cloud).
constexpr uint64_t kFaultStream = 0x6661756cULL, kSprayStream = 0x73707279ULL;
// Draws of the fault stream per firing: dropout, depth edge to the next cycle, rain (3).
constexpr uint64_t kDrawsPerFiring = 8;
constexpr uint64_t kDropoutDraw = 0, kEdgeDraw = 1, kRainDraw = 2, kRainRangeDraw = 3, kRainIntensityDraw = 4;
const char* const kRoadMaterials[] = {"asphalt", "sidewalk", "curb_concrete"};
const char* const kMarkingMaterials[] = {"lane_paint", "crosswalk_paint"};
const char* const kCarriagewayMaterials[] = {"asphalt", "lane_paint", "crosswalk_paint"};

bool is_one_of(const std::string& name, const auto& names) {
  for (const char* n : names)
    if (name == n) return true;
  return false;
}
}  // namespace

PoseAt constant_twist(const Eigen::Isometry3d& start, int64_t t0_ns, double v, double w) {
  return [=](int64_t t_ns) {
    const double t = double(t_ns - t0_ns) * 1e-9;
    const double yaw = w * t;
    // Exact integration of the unicycle: a straight line when w = 0, an arc otherwise.
    const double ds = std::abs(w) < 1e-9 ? v * t : v / w * std::sin(yaw);
    const double dl = std::abs(w) < 1e-9 ? 0.0 : v / w * (1 - std::cos(yaw));
    Eigen::Isometry3d pose = start;
    pose.translate(Eigen::Vector3d(ds, dl, 0));
    pose.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    return pose;
  };
}

LidarScanner::LidarScanner(const Hdl32eConfig& config, const MaterialTable& materials, const WeatherConfig& weather)
    : config_(config), weather_(weather), returns_(config), mount_(config.mount()), calibration_(config.calibration()) {
  // The mount is the frame the driver's points are in: a calibration fits the decoded clouds, so it
  // absorbs the mean lag between a cycle's azimuth reading and its firings. The head itself sits that
  // much counter-clockwise of it, and a cycle's rays straddle its reported azimuth, +-0.064 deg at 10 Hz.
  mount_.rotate(Eigen::AngleAxisd(config.mean_firing_lag_deg() * kDeg, Eigen::Vector3d::UnitZ()));
  for (size_t i = 0; i < materials.size(); ++i) {
    Material m = materials[MaterialId(i)];
    if (weather.wet && is_one_of(m.name, kRoadMaterials)) m.reflectivity *= weather.wet_road_factor;
    if (weather.wet && is_one_of(m.name, kMarkingMaterials)) m.reflectivity *= weather.wet_marking_factor;
    carriageway_.push_back(is_one_of(m.name, kCarriagewayMaterials));
    materials_.push_back(m);
  }
  // The head spins clockwise seen from above (yaw decreasing in the x-forward, y-left frame).
  const double yaw_rate = -2 * M_PI * config.rotation_hz;
  for (int slot = 0; slot < kHdl32eLasers; ++slot) {
    const double elevation = config.elevation_deg[config.firing_order[slot]] * kDeg;
    const double yaw = yaw_rate * double(slot * config.firing_period_ns) * 1e-9;
    slot_direction_[slot] = Eigen::Vector3f(float(std::cos(elevation) * std::cos(yaw)),
                                            float(std::cos(elevation) * std::sin(yaw)), float(std::sin(elevation)));
  }
  const int cycles = config.cycles_per_scan();
  const int per_keyframe =
      std::max(config.cycles_per_actor_update, (cycles + RayScene::kMaxKeyframes - 2) / (RayScene::kMaxKeyframes - 1));
  keyframes_ = (cycles + per_keyframe - 1) / per_keyframe + 1;
  keyframe_step_ns_ = per_keyframe * config.cycle_period_ns();
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const double yaw = config.scan_start_yaw_deg * kDeg + yaw_rate * double(config.firing_time_ns(cycle, 0)) * 1e-9;
    cycle_yaw_.emplace_back(float(std::cos(yaw)), float(std::sin(yaw)));
    cycle_azimuth_.push_back(hdl32e_azimuth(yaw));
  }
}

std::vector<LidarScanner::CyclePose> LidarScanner::cycle_poses(const PoseAt& vehicle_pose, int64_t stamp_ns) const {
  const int cycles = config_.cycles_per_scan();
  std::vector<CyclePose> poses(cycles);
  auto sensor_at = [&](int64_t t) { return vehicle_pose(t) * mount_; };
  if (!config_.motion_distortion) {
    const Eigen::Isometry3d p = sensor_at(stamp_ns);
    for (auto& c : poses) c = {p.linear().cast<float>(), p.translation().cast<float>(), Eigen::Vector3f::Zero()};
    return poses;
  }
  const double dt = double(config_.cycle_period_ns()) * 1e-9;
  Eigen::Isometry3d next = sensor_at(stamp_ns);
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const Eigen::Isometry3d now = next;
    next = sensor_at(stamp_ns + config_.firing_time_ns(cycle + 1, 0));
    poses[cycle] = {now.linear().cast<float>(), now.translation().cast<float>(),
                    ((next.translation() - now.translation()) / dt).cast<float>()};
  }
  return poses;
}

Eigen::Vector3f LidarScanner::sensor_direction(int cycle, int slot) const {
  const Eigen::Vector2f& cs = cycle_yaw_[cycle];
  const Eigen::Vector3f& d = slot_direction_[slot];
  return {cs.x() * d.x() - cs.y() * d.y(), cs.y() * d.x() + cs.x() * d.y(), d.z()};
}

LidarRay LidarScanner::ray(const CyclePose& pose, int cycle, int slot) const {
  const float dt = float(double(slot * config_.firing_period_ns) * 1e-9);
  const double time = double(config_.firing_time_ns(cycle, slot)) / double((keyframes_ - 1) * keyframe_step_ns_);
  return {pose.origin + pose.velocity * dt, pose.rotation * sensor_direction(cycle, slot), float(time)};
}

std::vector<LidarRay> LidarScanner::rays(const PoseAt& vehicle_pose, int64_t stamp_ns) const {
  const auto poses = cycle_poses(vehicle_pose, stamp_ns);
  std::vector<LidarRay> out;
  out.reserve(size_t(rays_per_scan()));
  for (int cycle = 0; cycle < int(poses.size()); ++cycle)
    for (int slot = 0; slot < kHdl32eLasers; ++slot) out.push_back(ray(poses[cycle], cycle, slot));
  return out;
}

PointCloud LidarScanner::scan(RayScene& scene, const PoseAt& vehicle_pose, int64_t stamp_ns, uint64_t seed,
                              const ActorPoses& actor_poses, Hdl32eRotation* wire, uint32_t lasers) const {
  const auto poses = cycle_poses(vehicle_pose, stamp_ns);
  const int cycles = int(poses.size());
  const CounterRng rng(seed, uint64_t(stamp_ns));
  const CounterRng faults(mix64(seed ^ kFaultStream), uint64_t(stamp_ns));
  const CounterRng spray_rng(mix64(seed ^ kSprayStream), uint64_t(stamp_ns));
  const size_t firings = size_t(cycles) * kHdl32eLasers;
  // What each firing measured: range (m, on the sensor's range resolution) and intensity.
  std::vector<float> ranges(firings, 0.0f);
  std::vector<uint8_t> intensities(firings, 0), valid(firings, 0);
  const float tnear = float(config_.min_range_m) * 0.5f, tfar = float(config_.max_range_m) * 1.05f;
  constexpr float kNoSurface = std::numeric_limits<float>::infinity();
  // For mixed returns: each firing's surface range and signal, and whether its point came from it.
  const bool mixing = config_.mixed_returns;
  std::vector<float> surface_range(mixing ? firings : 0, kNoSurface), surface_signal(mixing ? firings : 0, 0);
  const bool puddles = weather_.puddle_fraction > 0;
  const double rain_probability = weather_.rain_rate_mm_h * weather_.rain_clutter_per_mm_h;

  std::vector<SprayBox> spray;
  if (actor_poses && scene.actor_count() > 0) {
    std::vector<std::vector<Eigen::Isometry3d>> motion(scene.actor_count());
    std::vector<Eigen::Isometry3d> poses(scene.actor_count());
    for (int k = 0; k < keyframes_; ++k) {
      actor_poses(stamp_ns + k * keyframe_step_ns_, poses);
      for (size_t a = 0; a < poses.size(); ++a) motion[a].push_back(poses[a]);
    }
    if (weather_.spray && weather_.wet) spray = spray_boxes(motion);  // every keyframe of every actor
    // An actor standing still is one pose, not a motion: Embree then traverses it as a static
    // instance, not through a motion-blur BVH (a parked street's hundreds of cars).
    for (auto& m : motion)
      if (std::all_of(m.begin(), m.end(), [&](const Eigen::Isometry3d& p) { return p.isApprox(m.front(), 0); }))
        m.resize(1);
    for (size_t a = 0; a < motion.size(); ++a) scene.set_actor_motion(int(a), motion[a]);
    scene.commit();
  }
  const size_t spray_per_keyframe = spray.size() / size_t(keyframes_ - 1 > 0 ? keyframes_ - 1 : 1);

  // Spurious returns short of the surface (or of nothing): rain drops near the lens, spray behind
  // actors. Returns the nearest such range, or kNoSurface.
  auto clutter = [&](const LidarRay& ray, size_t i, float surface) {
    float nearest = surface;
    if (rain_probability > 0 && faults.uniform(kDrawsPerFiring * i + kRainDraw) < rain_probability) {
      const double r = config_.min_range_m - weather_.rain_clutter_range_m *
                                                 std::log(1.0 - faults.uniform(kDrawsPerFiring * i + kRainRangeDraw));
      nearest = std::min(nearest, float(r));
    }
    if (spray_per_keyframe > 0) {
      const size_t interval =
          std::min(size_t(keyframes_ - 2), size_t(std::max(0.0f, ray.time * float(keyframes_ - 1))));
      for (size_t b = 0; b < spray_per_keyframe; ++b) {
        const SprayBox& box = spray[interval * spray_per_keyframe + b];
        if (box.length <= 0) continue;  // that actor throws no spray in this interval
        const Eigen::Vector3f o = box.to_box * ray.origin, d = box.to_box.linear() * ray.direction;
        const Eigen::Vector3f lo(-box.length, -0.5f * float(weather_.spray_width_m), 0.0f),
            hi(0.0f, 0.5f * float(weather_.spray_width_m), float(weather_.spray_height_m));
        float t0 = tnear, t1 = std::min(nearest, tfar);
        for (int axis = 0; axis < 3 && t0 < t1; ++axis) {
          const float inv = 1.0f / d[axis];  // +-inf for a ray parallel to the slab: fine in IEEE
          float a = (lo[axis] - o[axis]) * inv, c = (hi[axis] - o[axis]) * inv;
          if (a > c) std::swap(a, c);
          t0 = std::max(t0, a), t1 = std::min(t1, c);
        }
        if (t0 >= t1) continue;
        // The first drop met along the path: exponential with the spray's density.
        const double t = t0 - std::log(1.0 - spray_rng.uniform(i * spray_per_keyframe + b)) / box.density;
        if (t < t1) nearest = float(t);
      }
    }
    return nearest;
  };

  // Rays travel in packets of the same laser over consecutive cycles: nearly parallel, so Embree's
  // packet traversal visits almost the same nodes for all of them.
  constexpr int kPacket = RayScene::kPacket;
  auto cast = [&](int first_cycle, int end_cycle) {
    const int groups = (end_cycle - first_cycle + kPacket - 1) / kPacket;
    tbb::parallel_for(tbb::blocked_range<int>(0, groups * kHdl32eLasers, 8), [&](const tbb::blocked_range<int>& range) {
      LidarRay rays[kPacket];
      RayHit hits[kPacket];
      bool found[kPacket];
      for (int packet = range.begin(); packet != range.end(); ++packet) {
        const int slot = packet % kHdl32eLasers, cycle0 = first_cycle + (packet / kHdl32eLasers) * kPacket;
        const int ring = config_.firing_order[slot];
        if (!((lasers >> ring) & 1u)) continue;
        const int count = std::min(kPacket, end_cycle - cycle0);
        for (int k = 0; k < count; ++k) rays[k] = ray(poses[cycle0 + k], cycle0 + k, slot);
        scene.intersect8(rays, count, tnear, tfar, hits, found);
        for (int k = 0; k < count; ++k) {
          const int cycle = cycle0 + k;
          const size_t i = size_t(cycle) * kHdl32eLasers + size_t(slot);
          // Standing water on the carriageway mirrors the beam away: no surface there.
          if (found[k] && puddles && carriageway_[hits[k].material]) {
            const Eigen::Vector3f p = rays[k].origin + rays[k].direction * hits[k].range;
            found[k] = !in_puddle(weather_, seed, p.x(), p.y());
          }
          const float surface = found[k] ? hits[k].range : kNoSurface;
          const float spurious = weather_.dry() ? kNoSurface : clutter(rays[k], i, surface);
          if (spurious < surface) {
            const double r = std::round(spurious / config_.range_resolution_m) * config_.range_resolution_m;
            if (r < config_.min_range_m || r > config_.max_range_m) continue;
            const double u = faults.uniform(kDrawsPerFiring * i + kRainIntensityDraw);
            ranges[i] = float(r);
            intensities[i] = uint8_t(std::lround(weather_.clutter_intensity * u));
            valid[i] = 1;
            continue;
          }
          if (!found[k]) continue;
          const Material& material = materials_[hits[k].material];
          const double cos_incidence = std::abs(double(hits[k].normal.dot(rays[k].direction)));
          if (mixing) {
            surface_range[i] = hits[k].range;
            surface_signal[i] = float(returns_.signal(material, hits[k].range, cos_incidence));
          }
          if (config_.dropout_probability > 0 &&
              faults.uniform(kDrawsPerFiring * i + kDropoutDraw) < config_.dropout_probability)
            continue;
          const auto ret = returns_(material, hits[k].range, cos_incidence, ring, rng, i);
          if (!ret) continue;
          ranges[i] = ret->range;
          intensities[i] = ret->intensity;
          valid[i] = 2;
        }
      }
    });
  };
  cast(0, cycles);
  if (mixing) mix_depth_edges(surface_range, surface_signal, valid, faults, ranges);

  // What the sensor sends (one block per cycle: the cycle's azimuth, 2 mm distance units, integer
  // intensities), and the points a driver makes of it: every laser of a block at the block's
  // azimuth, though its ray left up to 31 slots (0.13 deg at 10 Hz) later.
  Hdl32eRotation own;
  Hdl32eRotation& sent = wire ? *wire : own;
  sent = {stamp_ns, config_.cycle_period_ns(), std::vector<Hdl32eBlock>(size_t(cycles))};
  for (int cycle = 0; cycle < cycles; ++cycle) {
    Hdl32eBlock& block = sent.blocks[size_t(cycle)];
    block.azimuth = cycle_azimuth_[size_t(cycle)];
    for (int slot = 0; slot < kHdl32eLasers; ++slot) {
      const size_t i = size_t(cycle) * kHdl32eLasers + size_t(slot);
      // The range limits hold for what the sensor reports, a mixed range included.
      if (!valid[i] || ranges[i] < config_.min_range_m || ranges[i] > config_.max_range_m) continue;
      const long units = std::lround(double(ranges[i]) / kHdl32eDistanceUnitM);
      if (units <= 0 || units > std::numeric_limits<uint16_t>::max()) continue;  // not on the wire
      block.distance[size_t(slot)] = uint16_t(units);
      block.intensity[size_t(slot)] = intensities[i];
    }
  }
  return hdl32e_cloud(calibration_, stamp_ns, sent.blocks);
}

void LidarScanner::mix_depth_edges(const std::vector<float>& surface_range, const std::vector<float>& surface_signal,
                                   const std::vector<uint8_t>& from_surface, const CounterRng& faults,
                                   std::vector<float>& ranges) const {
  constexpr size_t L = kHdl32eLasers;
  const size_t cycles = surface_range.size() / L;
  // The angle between two firings of a laser, and the half width of its spot (both radians).
  const double step = 2 * M_PI * config_.rotation_hz * double(config_.cycle_period_ns()) * 1e-9;
  const double half = 0.5 * config_.beam_divergence_mrad * 1e-3;
  if (half <= 0 || cycles < 2) return;
  // Share of a spot centred `e` from an edge that lies beyond it (the spot is rectangular, manual).
  auto beyond = [&](double e) { return std::clamp((half - e) / (2 * half), 0.0, 0.5); };
  std::vector<float> shift(surface_range.size(), 0.0f);
  for (size_t slot = 0; slot < L; ++slot)
    for (size_t c = 0; c + 1 < cycles; ++c) {
      const size_t i = c * L + slot, j = i + L;
      const float ri = surface_range[i], rj = surface_range[j];
      if (!std::isfinite(ri) || !std::isfinite(rj)) continue;  // the sky takes no share of the range
      // A depth edge: the jump differs from the range trend on both sides.
      const double jump = double(rj) - ri;
      const double left = c > 0 && std::isfinite(surface_range[i - L]) ? double(ri) - surface_range[i - L] : 0.0;
      const double right =
          c + 2 < cycles && std::isfinite(surface_range[j + L]) ? surface_range[j + L] - double(rj) : 0.0;
      if (std::abs(jump - left) <= config_.mixed_edge_step_m || std::abs(jump - right) <= config_.mixed_edge_step_m)
        continue;
      if (std::abs(jump) >= config_.pulse_length_m) continue;                   // two echoes, resolved: no mix
      const double e = step * faults.uniform(kDrawsPerFiring * i + kEdgeDraw);  // edge from beam i's centre
      const double fi = beyond(e), fj = beyond(step - e), si = surface_signal[i], sj = surface_signal[j];
      // Each surface's share of the merged echo: its share of the spot times its signal.
      if (fi > 0 && sj > 0) shift[i] += float(jump * fi * sj / (fi * sj + (1 - fi) * si));
      if (fj > 0 && si > 0) shift[j] -= float(jump * fj * si / (fj * si + (1 - fj) * sj));
    }
  for (size_t i = 0; i < shift.size(); ++i) {
    if (shift[i] == 0 || from_surface[i] != 2) continue;
    double mixed = double(ranges[i]) + shift[i];
    if (config_.range_resolution_m > 0)
      mixed = std::round(mixed / config_.range_resolution_m) * config_.range_resolution_m;
    ranges[i] = float(mixed);
  }
}

std::vector<LidarScanner::SprayBox> LidarScanner::spray_boxes(
    const std::vector<std::vector<Eigen::Isometry3d>>& motion) const {
  std::vector<SprayBox> boxes;  // keyframe-interval-major, then actor
  const double dt = double(keyframe_step_ns_) * 1e-9;
  for (int k = 0; k + 1 < keyframes_; ++k)
    for (const auto& keys : motion) {
      const Eigen::Isometry3d &a = keys[size_t(k)], &b = keys[size_t(k) + 1];
      const double speed = (b.translation() - a.translation()).norm() / dt;
      SprayBox box{Eigen::Isometry3f::Identity(), 0.0f, 1.0f};
      if (speed >= weather_.spray_min_speed_mps) {
        // The box trails from spray_offset_m behind the actor's origin, level, along its heading.
        const Eigen::Vector3d forward = a.linear().col(0);
        const double yaw = std::atan2(forward.y(), forward.x());
        Eigen::Isometry3d box_pose = Eigen::Isometry3d::Identity();
        box_pose.translate(a.translation() -
                           weather_.spray_offset_m * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0));
        box_pose.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
        box.to_box = box_pose.inverse().cast<float>();
        box.length = float(speed * weather_.spray_length_s);
        box.density = float(weather_.spray_density_per_m * std::min(1.0, speed / WeatherConfig::kSprayFullSpeedMps));
      }
      boxes.push_back(box);  // length 0: no spray, a ray never meets it
    }
  return boxes;
}

}  // namespace lidarloop
