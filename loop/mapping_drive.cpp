#include "loop/mapping_drive.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/units.hpp"
#include "sim/actor_assets.hpp"
#include "sim/hdl32e.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/path.hpp"
#include "sim/road_surface.hpp"
#include "sim/traffic.hpp"
#include "sim/vehicle_model.hpp"

namespace lidarloop {

namespace {

constexpr double kTrafficSpacing = 45.0;  // m between oncoming vehicles
constexpr double kTrafficSpeed = 9.0;     // m/s
constexpr double kRestStep = 0.1;         // m: pitch and roll follow roughness of 0.5 m wavelength and more
constexpr ActorType kTrafficTypes[] = {ActorType::car, ActorType::car, ActorType::truck, ActorType::bus};

}  // namespace

std::string MappingOptions::describe() const {
  std::ostringstream s;
  s << "traffic=" << traffic << " speed=" << speed << " resolution=" << resolution << " tile_cells=" << tile_cells
    << " max_ground_height=" << max_ground_height << " max_range=" << max_range << " seed=" << seed
    << " survey_unit_serial=" << survey_unit_serial << " " << survey_error.describe();
  if (ideal_ground) s << " ideal_ground=1";  // absent when off, so typical maps keep their cache key
  return s.str();
}

MappingOptions mapping_options_for(Realism realism) {
  MappingOptions o;
  switch (realism) {
    case Realism::ideal:
      o.survey_error.sigma_xy_m = 0;
      o.survey_error.heading_sigma_rad = 0;
      o.survey_unit_serial = Hdl32eConfig{}.unit_serial;  // the test car's own unit
      o.ideal_ground = true;
      break;
    case Realism::typical:
      break;  // the defaults: an RTK-INS survey (SurveyErrorConfig)
    case Realism::harsh:
      // A survey driven without an RTK fix (code-differential GNSS aiding the INS). Assumption: the
      // position error five times the RTK column's 2 cm and the heading error twice its 0.05 deg; the
      // Applanix datasheet's DGPS column is worse still (decimetres), so this is a mild "harsh".
      o.survey_error.sigma_xy_m = 0.10;
      o.survey_error.heading_sigma_rad = 0.10 * kDeg;
      break;
  }
  return o;
}

LoadedWorld load_mapped_world(const std::string& world, const MappingOptions& options) {
  LoadedWorld w = load_world(world);
  if (options.ideal_ground) {
    w.description = on_ideal_ground(std::move(w.description));
    w.world = build_world(w.description, w.materials, actors_dir());
  }
  return w;
}

void read_survey_options(const YamlReader& yaml, const YAML::Node& node, MappingOptions& o) {
  // Ranges that catch typos (a sigma in cm, a heading in rad), not physical limits.
  constexpr double kMaxSigma = 10.0, kMaxHeadingSigmaDeg = 10.0, kMinLength = 0.01, kMaxLength = 1e7,
                   kMaxSpacing = 10.0;
  SurveyErrorConfig& e = o.survey_error;
  YamlMap(yaml, node, "survey")
      .integer("unit_serial", o.survey_unit_serial, 0, uint64_t(1) << 40)
      .number("sigma_xy_m", e.sigma_xy_m, 0.0, kMaxSigma)
      .number("correlation_length_m", e.correlation_length_m, kMinLength, kMaxLength)
      .degrees("heading_sigma_deg", e.heading_sigma_rad, 0.0, kMaxHeadingSigmaDeg)
      .number("heading_correlation_length_m", e.heading_correlation_length_m, kMinLength, kMaxLength)
      .number("sample_spacing_m", e.sample_spacing_m, kMinLength, kMaxSpacing)
      .done();
}

SurveyDrive mapping_survey(const WorldDescription& description, const MappingOptions& o) {
  std::mt19937_64 rng(o.seed);
  return plan_survey(description, o.survey_error, rng);
}

CurbMap surveyed_curbs(const World& world, const SurveyDrive& survey, const MappingOptions& o) {
  return survey_curb_map(densify_curb_map(world.curb_map(), o.survey_error.sample_spacing_m), survey);
}

IntensityMapBuilder run_mapping_drive(const WorldDescription& description, const World& world,
                                      const MaterialTable& materials, const std::string& actors_dir,
                                      const MappingOptions& o, const std::string& world_hash,
                                      const std::function<void(double)>& progress) {
  IntensityMapHeader header;
  header.world = description.name;
  header.world_hash = world_hash;
  header.build["mapping"] = o.describe();
  header.origin = description.origin;
  header.resolution_m = o.resolution;
  header.tile_cells = o.tile_cells;
  IntensityMapBuilder builder(header);

  // The survey unit, of its own serial, calibrated in situ by the surveyors (no range biases or
  // intensity offsets left, no mixed returns or dropouts modelled), on a dry day: the map is the same
  // whatever the scenario's realism profile and weather.
  Hdl32eConfig lidar = hdl32e_config_for(Realism::ideal);
  lidar.unit_serial = o.survey_unit_serial;
  const LidarScanner scanner(lidar, materials, weather_config_for(Realism::ideal));
  const Eigen::Isometry3d mount = lidar.mount();
  const GroundHeight pavement = world.pavement();
  const VehicleParams survey_car;
  const int64_t period = lidar.scan_period_ns();
  const SurveyDrive survey = mapping_survey(description, o);

  for (const SurveyLane& lane : survey.lanes) {
    const Path& path = lane.path;
    // A fresh scene per lane, with oncoming traffic on the other side of this road if asked.
    RayScene scene(world.mesh);
    std::vector<ActorPlan> traffic;
    if (o.traffic && !lane.road->one_way) {
      const Path other = lane_path(*lane.road, Lane::right, !lane.backward);
      for (double s = kTrafficSpacing / 2; s < other.length; s += kTrafficSpacing) {
        ActorPlan a;
        a.type = kTrafficTypes[traffic.size() % std::size(kTrafficTypes)];
        a.path = other;
        a.start_s = s;
        a.speed = kTrafficSpeed;
        traffic.push_back(a);
      }
      add_actors(scene, traffic, actors_dir, materials);
    }
    const ActorPoses actor_poses = actor_motion(traffic);
    // The car is where the truth says, resting on the crowned, rough road; its scans are placed where
    // the survey says: the survey's plan position and heading error moves the whole body.
    // Resting poses every kRestStep along the lane; between them the car moves in the plane with the
    // last one's height, pitch and roll (finding them costs four ground lookups, and a scan has 2170
    // firing cycles).
    std::vector<Eigen::Isometry3d> rest(size_t(path.length / kRestStep) + 2);
    for (size_t k = 0; k < rest.size(); ++k)
      rest[k] =
          rest_on_ground(path.pose_at(double(k) * kRestStep), pavement, survey_car.wheelbase(), survey_car.track_width);
    const PoseAt vehicle = [&](int64_t t) {
      const double s = o.speed * ns_to_s(t);
      const size_t k = std::min(rest.size() - 1, size_t(std::max(0.0, s / kRestStep)));
      return to_isometry(path.pose_at(s)) * to_isometry(path.pose_at(double(k) * kRestStep)).inverse() * rest[k];
    };
    const PoseAt surveyed = [&](int64_t t) {
      const double s = o.speed * ns_to_s(t);
      const Pose2d truth = path.pose_at(s);
      const Eigen::Isometry3d error =
          to_isometry(surveyed_pose(truth, survey.error.at(lane.start_m + s))) * to_isometry(truth).inverse();
      return error * vehicle(t);
    };
    const int64_t scans = int64_t(path.length / o.speed / (double(period) * 1e-9));
    for (int64_t k = 0; k < scans; ++k) {
      const int64_t stamp = k * period;
      const PointCloud cloud = scanner.scan(scene, vehicle, stamp, o.seed, actor_poses);
      // The survey places each point with its pose at the point's own firing cycle.
      uint32_t cycle = UINT32_MAX;
      Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
      for (const LidarPoint& p : cloud.points) {
        if (double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z > o.max_range * o.max_range) continue;
        if (p.intensity > 100) continue;  // a sign or a reflector, not the road surface
        const uint32_t c = uint32_t(p.t_ns / lidar.cycle_period_ns());
        if (c != cycle) cycle = c, body = surveyed(stamp + int64_t(c) * lidar.cycle_period_ns());
        // Higher than this above the ground under the car, a point cannot be ground. Level, not in the
        // plane of the wheels: on a 2 % crown that plane is 0.4 m off at 20 m across the road.
        const Eigen::Vector3d w = body * (mount * Eigen::Vector3d(p.x, p.y, p.z));
        if (w.z() - body.translation().z() > o.max_ground_height) continue;
        builder.add(w.head<2>(), p.intensity);
      }
      if (progress) progress((lane.start_m + o.speed * ns_to_s(stamp)) / survey.length_m);
    }
  }
  return builder;
}

}  // namespace lidarloop
