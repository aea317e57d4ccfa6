#include "sim/simulation.hpp"

#include <algorithm>
#include <cmath>

#include "common/units.hpp"

namespace lidarloop {

constexpr int64_t kControlPeriodNs = 10'000'000;  // the driver acts at 100 Hz
constexpr int64_t kTruthPeriodNs = 10'000'000;    // ground truth recorded at 100 Hz
// Seeds of the sensors' random streams, derived from the scenario seed so each is independent.
constexpr uint64_t kCanStream = 1, kGpsStream = 2, kRtkStream = 3, kLidarStream = 4;
constexpr uint64_t kLidarClockStream = 0x6c6964636c6f636b;  // "lidclock"

namespace {

// The ground plane under the ego's wheels, where its suspension is attached (unused by a rigid body).
GroundPlane plane_under(const Pose2d& rear_axle, const GroundContact& contact, const VehicleParams& v,
                        const BodyConfig& body) {
  if (body.rigid) return {};
  return ground_plane(on_ground(rear_axle, contact), v.lr);
}

GroundContact contact_of(const Pose2d& rear_axle, const GroundHeight& pavement, const VehicleParams& v) {
  return ground_contact(rear_axle, pavement, v.wheelbase(), v.track_width);
}

}  // namespace

Simulation::Simulation(const Scenario& scenario, const WorldDescription& description, const World& world,
                       const MaterialTable& materials, const std::string& actors_dir, int threads)
    : scenario_(scenario),
      resolved_(resolve_scenario(scenario, description, world)),
      scene_(std::make_unique<RayScene>(world.mesh, threads)),
      mount_draw_(draw_mount_error(scenario.mount_error, scenario.seed)),
      true_lidar_mount_(with_true_mount(scenario.lidar, mount_draw_).mount()),
      lidar_clock_rng_(scenario.seed, kLidarClockStream),
      scanner_(with_true_mount(scenario.lidar, mount_draw_), materials, scenario.weather),
      vehicle_(scenario.ego.vehicle,
               VehicleModel::state_at(scenario.ego.vehicle, resolved_.ego_route.pose_at(scenario.ego.start_at),
                                      scenario.ego.initial_speed)),
      controller_(resolved_.ego_route, scenario.ego.speed, scenario.ego.stops, scenario.ego.vehicle,
                  scenario.ego.controller),
      can_(scenario.can, mix64(scenario.seed ^ kCanStream), scenario.clocks.can),
      gps_(with_true_antenna(scenario.gps, mount_draw_), LocalFrame(description.origin),
           mix64(scenario.seed ^ kGpsStream)),
      rtk_(scenario.rtk, LocalFrame(description.origin), mix64(scenario.seed ^ kRtkStream)),
      control_period_ns_(kControlPeriodNs),
      ground_(world.ground()),
      pavement_(world.pavement()),
      body_(
          scenario.body, scenario.ego.vehicle,
          plane_under(vehicle_.rear_axle_pose(), contact_of(vehicle_.rear_axle_pose(), pavement_, scenario.ego.vehicle),
                      scenario.ego.vehicle, scenario.body)) {
  add_actors(*scene_, resolved_.actors, actors_dir, materials, ground_);
  actor_poses_ = actor_motion(resolved_.actors, ground_);
  curb_tops_ = curb_top_samples(world, curb_visibility_.spacing_m);
  trajectory_.push_back(vehicle_.rear_axle_pose());
  body_trajectory_.push_back(body_.attitude());
  ground_trajectory_.push_back(contact_of(vehicle_.rear_axle_pose(), pavement_, scenario.ego.vehicle));
  for (const KidnapFault& k : scenario.kidnaps)
    if (k.moves == KidnapMoves::car) car_kidnaps_.push_back(k);
  std::stable_sort(car_kidnaps_.begin(), car_kidnaps_.end(),
                   [](const KidnapFault& a, const KidnapFault& b) { return a.at_s < b.at_s; });
  if (kidnap_the_car()) start_trajectory_here();  // one due at the first scan's start
}

Simulation::~Simulation() = default;

void Simulation::set_pose_source(std::function<Pose2d(int64_t, const Pose2d&)> source) {
  pose_source_ = std::move(source);
}

void Simulation::run(StreamSink& sink, const std::function<void(double)>& progress) {
  const int64_t chunk = scenario_.lidar.scan_period_ns() * 10;
  while (now_ < end_ns()) {
    advance_to(std::min(end_ns(), now_ + chunk), sink);
    if (progress) progress(double(now_) / double(end_ns()));
  }
}

void Simulation::advance_to(int64_t t_ns, StreamSink& sink) {
  t_ns = std::min(t_ns, end_ns());
  while (now_ + scenario_.ego.vehicle.step_ns <= t_ns) step(sink);
}

void Simulation::step(StreamSink& sink) {
  const VehicleParams& vp = scenario_.ego.vehicle;
  if (now_ % control_period_ns_ == 0) {
    const Pose2d truth = vehicle_.rear_axle_pose();
    const Pose2d believed = pose_source_ ? pose_source_(now_, truth) : truth;
    command_ = controller_.update(now_, believed, vehicle_.state().vx);
  }
  const VehicleState before = vehicle_.state();
  vehicle_.step(command_.command);
  now_ += vp.step_ns;
  Pose2d pose = vehicle_.rear_axle_pose();
  trajectory_.push_back(pose);
  ground_trajectory_.push_back(contact_of(pose, pavement_, vp));
  if (!scenario_.body.rigid) {
    const double dt = ns_to_s(vp.step_ns);
    body_.step(dt, planar_acceleration(before, vehicle_.state(), dt),
               plane_under(pose, ground_trajectory_.back(), vp, scenario_.body));
  }
  body_trajectory_.push_back(body_.attitude());
  // A scan ends here. A kidnap of the car due now happens at this instant: the scan that ends was cast
  // from the old place (its trajectory above), everything stamped from now on comes from the new one.
  const bool scan_ends = now_ - trajectory_start_ns_ >= scenario_.lidar.scan_period_ns();
  const bool kidnapped = scan_ends && kidnap_the_car();
  if (kidnapped) pose = vehicle_.rear_axle_pose();

  if (now_ % can_.period_ns() == 0) can_.measure(now_, vehicle_.wheel_speeds(), vehicle_.steering_wheel_angle());
  for (const CanFrame& f : can_.deliver(now_)) sink.on_can(f);
  if (now_ % kTruthPeriodNs == 0) {
    const VehicleState& s = vehicle_.state();
    sink.on_truth({now_, pose, s.vx, s.yaw_rate, s.steer, command_.cross_track, body_.attitude()});
  }
  if (now_ % gps_.period_ns() == 0) sink.on_gps(gps_.sample(now_, pose));
  if (now_ % rtk_.period_ns() == 0) sink.on_rtk(rtk_.sample(now_, pose));
  if (scan_ends) emit_scan(sink);
  if (kidnapped) start_trajectory_here();
}

void Simulation::start_trajectory_here() {
  const Pose2d pose = vehicle_.rear_axle_pose();
  trajectory_.assign(1, pose);
  ground_trajectory_.assign(1, contact_of(pose, pavement_, scenario_.ego.vehicle));
  body_trajectory_.assign(1, body_.attitude());
}

// At a scan's end, so that no scan is cast from both places: at the scan boundary nearest each kidnap's
// time (from half a scan period before it), as the belief's kidnaps are done (loop/kidnap_schedule.hpp).
// The body is set down on the new ground with its attitude on it. Whether the car moved.
bool Simulation::kidnap_the_car() {
  bool moved = false;
  for (; next_car_kidnap_ < car_kidnaps_.size(); ++next_car_kidnap_) {
    const KidnapFault& k = car_kidnaps_[next_car_kidnap_];
    if (kidnap_scan_start_ns(k, scenario_.lidar.scan_period_ns()) > now_) break;
    vehicle_.place(vehicle_.rear_axle_pose().compose({k.offset_m.x(), k.offset_m.y(), k.yaw_rad}));
    if (!pose_source_) controller_.jumped(k.offset_m.x());  // closed loop: it steers on the belief, which stayed
    moved = true;
  }
  if (moved) {
    const VehicleParams& vp = scenario_.ego.vehicle;
    const Pose2d pose = vehicle_.rear_axle_pose();
    body_.set_down(plane_under(pose, contact_of(pose, pavement_, vp), vp, scenario_.body));
  }
  return moved;
}

void Simulation::emit_scan(StreamSink& sink) {
  // The scan that started at trajectory_start_ns_ is complete: the vehicle's path through it is known.
  // Every firing is cast from the body's pose at its time: the ground plane under the wheels at the
  // rear axle's pose, times the body's attitude on it (the LiDAR mount is on the body). The wheels'
  // contact is found at every integration step (at most 1 ms: 3 cm at 30 m/s, a sixteenth of the
  // shortest roughness wave) and interpolated between, as the body's attitude is: a firing cycle
  // lasts 55 us, and finding the contact costs four lookups of the pavement's height.
  const int64_t stamp = trajectory_start_ns_, step_ns = scenario_.ego.vehicle.step_ns;
  const std::vector<Pose2d>& poses = trajectory_;
  const std::vector<BodyAttitude>& bodies = body_trajectory_;
  const std::vector<GroundContact>& contacts = ground_trajectory_;
  const bool rigid = scenario_.body.rigid;
  const PoseAt vehicle_pose = [&](int64_t t) {
    const double u = double(t - stamp) / double(step_ns);
    const size_t i = std::min(poses.size() - 2, size_t(std::max(0.0, std::floor(u))));
    const double f = std::clamp(u - double(i), 0.0, 1.0);
    const Pose2d &a = poses[i], &b = poses[i + 1];
    const GroundContact &ca = contacts[i], &cb = contacts[i + 1];
    const Eigen::Isometry3d ground =
        on_ground({a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), a.yaw + f * wrap_angle(b.yaw - a.yaw)},
                  {ca.z + f * (cb.z - ca.z), ca.pitch + f * (cb.pitch - ca.pitch), ca.roll + f * (cb.roll - ca.roll)});
    if (rigid) return ground;
    BodyAttitude body = bodies[i];
    body.heave += f * (bodies[i + 1].heave - body.heave);
    body.pitch += f * (bodies[i + 1].pitch - body.pitch);
    body.roll += f * (bodies[i + 1].roll - body.roll);
    return Eigen::Isometry3d(ground * body.pose());
  };
  PointCloud cloud =
      scanner_.scan(*scene_, vehicle_pose, stamp, mix64(scenario_.seed ^ kLidarStream), actor_poses_, &rotation_);
  // The LiDAR's clock stamps the scan; the truth (sensor pose, actors) stays on the reference clock.
  cloud.stamp_ns = stamp_on(scenario_.clocks.lidar, stamp, lidar_clock_rng_, uint64_t(scan_index_));
  const Eigen::Isometry3d sensor_pose = vehicle_pose(stamp) * true_lidar_mount_;
  sink.on_scan(cloud, sensor_pose);
  sink.on_lidar_rotation(rotation_, cloud.stamp_ns);
  std::vector<ActorSample> states;
  for (const auto& a : resolved_.actors) states.push_back({a.name, a.type, actor_pose2d(a, stamp)});
  sink.on_actors(stamp, states);
  // The scene still holds this scan's actor keyframes, so ray time 0 is the scan's first firing: the
  // instant of the sensor pose and the actors above.
  CurbVisibility curbs =
      curb_visibility(*scene_, curb_tops_, sensor_pose.translation().cast<float>(), 0, curb_visibility_);
  curbs.stamp_ns = stamp;
  sink.on_curb_visibility(curbs);
  ++scan_index_;
  trajectory_.erase(trajectory_.begin(), trajectory_.end() - 1);
  body_trajectory_.erase(body_trajectory_.begin(), body_trajectory_.end() - 1);
  ground_trajectory_.erase(ground_trajectory_.begin(), ground_trajectory_.end() - 1);
  trajectory_start_ns_ = now_;
}

}  // namespace lidarloop
