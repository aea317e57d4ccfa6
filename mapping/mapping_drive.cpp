#include "mapping/mapping_drive.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "common/crc32.hpp"
#include "common/units.hpp"
#include "sim/actor_assets.hpp"
#include "sim/counter_rng.hpp"
#include "sim/hdl32e.hpp"
#include "sim/lidar_scanner.hpp"
#include "sim/path.hpp"
#include "sim/road_surface.hpp"
#include "sim/traffic.hpp"
#include "sim/vehicle_model.hpp"

namespace lidarloop {

namespace {

constexpr double kTrafficSpacing = 45.0;         // m between oncoming vehicles
constexpr double kTrafficSpeed = 9.0;            // m/s
constexpr double kCastMargin = 1.0;              // m cast beyond max_range: 50 times the range noise (2 cm)
constexpr double kRestStep = 0.1;                // m: pitch and roll follow roughness of 0.5 m wavelength and more
constexpr double kAboveTiltMargin = 0.1 * kDeg;  // rad: a laser this far above the sensor's tilt looks up
constexpr ActorType kTrafficTypes[] = {ActorType::car, ActorType::car, ActorType::truck, ActorType::bus};

// The lasers that can give the intensity layer a point, the others being aimed higher above the sensor's
// horizon than the sensor is tilted (by its body and mount) during the scan: their points all lie
// above the sensor, which stands more than max_ground_height over the ground under the car. Points
// that high are dropped anyway, and on level ground a quarter of the lasers look that high.
uint32_t ground_lasers(const Hdl32eConfig& lidar, const std::vector<Eigen::Isometry3d>& vehicle_at_cycle,
                       double max_ground_height) {
  double tilt = 0, height = std::numeric_limits<double>::infinity();
  for (const Eigen::Isometry3d& vehicle : vehicle_at_cycle) {
    const Eigen::Isometry3d sensor = vehicle * lidar.mount();
    // The angle between the sensor's axis and the vertical: a beam at elevation e points at least
    // e - tilt above the horizon.
    tilt = std::max(tilt, std::acos(std::clamp(sensor.linear()(2, 2), -1.0, 1.0)));
    height = std::min(height, sensor.translation().z() - vehicle.translation().z());
  }
  if (!(height > max_ground_height)) return LidarScanner::kAllLasers;
  uint32_t lasers = 0;
  for (int laser = 0; laser < kHdl32eLasers; ++laser)
    if (lidar.elevation_deg[size_t(laser)] * kDeg - tilt <= kAboveTiltMargin) lasers |= 1u << laser;
  return lasers;
}

}  // namespace

std::string MappingOptions::describe() const {
  std::ostringstream s;
  s << "traffic=" << traffic << " speed=" << speed << " resolution=" << resolution << " tile_cells=" << tile_cells
    << " max_ground_height=" << max_ground_height << " max_range=" << max_range << " seed=" << seed
    << " survey_unit_serial=" << survey_unit_serial << " " << survey_error.describe()
    << " point_voxel=" << point_voxel_m << " point_scan_stride=" << point_scan_stride;
  if (ideal_ground) s << " ideal_ground=1";  // absent when off, so typical maps keep their cache key
  if (!curb_label.is_default()) s << " " << curb_label.describe();  // the same
  // Uniform paint adds nothing, so the maps made before worn paint keep their keys.
  if (const std::string p = paint.describe_survey(); !p.empty()) s << " " << p;
  if (!parked.empty()) {  // the cars' places, as a checksum: hundreds of them would not fit the header
    std::ostringstream cars;
    for (const ActorPlan& a : parked) {
      const Pose2d p = actor_pose2d(a, 0);
      cars << actor_type_name(a.type) << " " << p.x << " " << p.y << " " << p.yaw << "\n";
    }
    Crc32 crc;
    crc.update(cars.str().data(), cars.str().size());
    s << " parked=" << parked.size() << "/" << std::hex << crc.value() << std::dec;
  }
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
      o.paint = paint_config_for(realism);
      break;
    case Realism::typical:
      break;  // the defaults: an RTK-INS survey (SurveyErrorConfig)
    case Realism::harsh:
      // A map made without an RTK-INS survey, as most research fleets make theirs: a GNSS-anchored
      // LiDAR-SLAM map (mapping/slam_map_error.hpp, its sourced defaults: 15 cm absolute, 3 cm relative
      // over 20 m). Chosen over the RTK model with larger sigmas (what harsh was: 10 cm, 0.1 deg, an
      // assumption) because it is how such maps are actually made and its figures have sources.
      o.survey_error.provenance = MapProvenance::slam;
      // Its curbs drawn by a labeller on the SLAM point cloud. Assumption: at the top edge of the face,
      // where the cloud's height changes, which is not the foot the curb detector finds on sloped and
      // rolled curbs (on vertical curbs the two coincide), with 3 cm of noise (about the point spacing
      // of a survey cloud at the curb; no published figure found).
      o.curb_label.convention = CurbLabel::face_top;
      o.curb_label.noise_m = 0.03;
      o.paint = paint_config_for(realism);
      break;
  }
  return o;
}

LoadedWorld load_mapped_world(const std::string& world, const MappingOptions& options) {
  WorldDescription description = load_world_description_of(world);
  if (options.ideal_ground) description = on_ideal_ground(std::move(description));
  description.paint = PaintConditions{options.paint, PaintDay::survey};
  return build_loaded_world(std::move(description));
}

void read_survey_options(const YamlReader& yaml, const YAML::Node& node, MappingOptions& o) {
  // Ranges that catch typos (a sigma in cm, a heading in rad), not physical limits.
  constexpr double kMaxSigma = 10.0, kMaxHeadingSigmaDeg = 10.0, kMinLength = 0.01, kMaxLength = 1e7,
                   kMaxSpacing = 10.0, kMaxLabelNoise = 1.0;
  SurveyErrorConfig& e = o.survey_error;
  YamlMap m(yaml, node, "survey");
  if (const YAML::Node p = m["provenance"]) {
    const std::string text = yaml.string(p, "provenance");
    if (text == "rtk_ins")
      e.provenance = MapProvenance::rtk_ins;
    else if (text == "slam")
      e.provenance = MapProvenance::slam;
    else
      yaml.fail(p, "provenance must be rtk_ins or slam, got '" + text + "'");
  }
  if (const YAML::Node l = m["curb_label"]) {
    const std::string text = yaml.string(l, "curb_label");
    if (text == "face_foot")
      o.curb_label.convention = CurbLabel::face_foot;
    else if (text == "face_top")
      o.curb_label.convention = CurbLabel::face_top;
    else if (text == "gutter_line")
      o.curb_label.convention = CurbLabel::gutter_line;
    else
      yaml.fail(l, "curb_label must be face_foot, face_top or gutter_line, got '" + text + "'");
  }
  // A figure of the other provenance's model would be ignored: say so rather than drop it.
  const bool slam = e.provenance == MapProvenance::slam;
  for (const char* key : {"sigma_xy_m", "correlation_length_m", "heading_sigma_deg", "heading_correlation_length_m"})
    if (slam && m[key]) yaml.fail(m[key], std::string(key) + " applies to provenance rtk_ins; this survey is slam");
  for (const char* key : {"slam_absolute_m", "slam_relative_m", "slam_relative_over_m"})
    if (!slam && m[key]) yaml.fail(m[key], std::string(key) + " applies to provenance slam; this survey is rtk_ins");
  m.integer("unit_serial", o.survey_unit_serial, 0, uint64_t(1) << 40)
      .number("sigma_xy_m", e.sigma_xy_m, 0.0, kMaxSigma)
      .number("correlation_length_m", e.correlation_length_m, kMinLength, kMaxLength)
      .degrees("heading_sigma_deg", e.heading_sigma_rad, 0.0, kMaxHeadingSigmaDeg)
      .number("heading_correlation_length_m", e.heading_correlation_length_m, kMinLength, kMaxLength)
      .number("slam_absolute_m", e.slam.absolute_sigma_m, kMinLength, kMaxSigma)
      .number("slam_relative_m", e.slam.relative_sigma_m, kMinLength, kMaxSigma)
      .number("slam_relative_over_m", e.slam.relative_over_m, kMinLength, kMaxLength)
      .number("sample_spacing_m", e.sample_spacing_m, kMinLength, kMaxSpacing)
      .number("label_noise_m", o.curb_label.noise_m, 0.0, kMaxLabelNoise)
      .number("label_noise_correlation_m", o.curb_label.noise_correlation_m, kMinLength, kMaxLength)
      .boolean("parked_on_survey_day", o.parked_on_survey_day);
  m.done();
  if (slam) {
    try {
      slam_correlation_length(e.slam);
    } catch (const std::invalid_argument& error) {
      yaml.fail(m.node(), error.what());
    }
  }
}

std::vector<ActorPlan> survey_day_parking(const ParkingConfig& parking, const WorldDescription& description,
                                          uint64_t mapping_seed) {
  constexpr uint64_t kSurveyDayStream = 0x7375727665796461;  // "surveyda"
  StreetUse street;
  street.parking = parking;
  std::vector<ActorPlan> cars;
  for (StreetActor& a : street_actors(street, description, 0, mix64(mapping_seed ^ kSurveyDayStream), 0))
    cars.push_back(std::move(a.plan));
  return cars;
}

SurveyDrive mapping_survey(const WorldDescription& description, const MappingOptions& o) {
  std::mt19937_64 rng(o.seed);
  return plan_survey(description, o.survey_error, rng);
}

CurbMap surveyed_curbs(const World& world, const SurveyDrive& survey, const MappingOptions& o) {
  const CurbMap dense = densify_curb_map(world.curb_map(), o.survey_error.sample_spacing_m);
  if (o.curb_label.is_default()) return survey_curb_map(dense, survey);  // no engine: the map it always was
  // The labeller's draws come from an engine of their own (stream kLabelStream of the seed).
  constexpr uint32_t kLabelStream = 0x6c61626c;  // "labl"
  std::seed_seq seeds{uint32_t(o.seed), uint32_t(o.seed >> 32), kLabelStream};
  std::mt19937_64 rng(seeds);
  const std::vector<std::vector<CurbStation>> no_band;
  const auto& rings = world.curb_band ? world.curb_band->rings() : no_band;
  return survey_curb_map(label_curb_map(dense, rings, o.curb_label, rng), survey);
}

namespace {

// Work items: a lane is driven in parts of kPartScans scans (24 m at 15 m/s), cast in parallel, each
// into a small builder of its own whose blocks of kPartTileCells cells are made only where its points
// fall. The parts are merged into the map in a fixed order, so the map's bytes are the same at any
// thread count; a tile is handed over (written) once the last part that can reach it is merged.
constexpr int64_t kPartScans = 16;
constexpr int kPartTileCells = 32;
// m added to how far a part's points can lie from its path: the path is sampled every kReachStep, and
// the body's pitch and roll move the sensor by centimetres.
constexpr double kReachStep = 1.0, kReachSlack = 2.0;
// Parts in flight per worker thread: enough to keep every core busy while one waits to be merged.
constexpr int kPartsInFlightPerThread = 2;

struct DrivePart {
  size_t lane;
  int64_t first_scan, end_scan;
  std::vector<std::pair<int, int>> tiles;  // of the map, that its points can reach
  std::pair<int, int> where;               // the tile of its middle: parts are merged in tile order
};

// Everything the parts of a drive share (read only while they run).
struct DriveSetup {
  const World& world;
  const MaterialTable& materials;
  const std::string& actors_dir;
  const MappingOptions& o;
  const SurveyDrive& survey;
  const Hdl32eConfig& lidar;
  const LidarScanner& scanner;
  // The world alone, shared by the parts: scan() changes a scene only to move its actors, and this one
  // has none. Lanes with traffic make their own.
  RayScene& scene;
  const GroundHeight& pavement;
  const GroundHeight& ground;  // where the actors stand (World::ground)
};

std::vector<ActorPlan> oncoming_traffic(const SurveyLane& lane, const MappingOptions& o) {
  std::vector<ActorPlan> traffic;
  if (!o.traffic || !lane.road || lane.road->one_way) return traffic;  // no oncoming lane known on a lanelet chain
  const Path other = lane_path(*lane.road, Lane::right, !lane.backward);
  for (double s = kTrafficSpacing / 2; s < other.length; s += kTrafficSpacing) {
    ActorPlan a;
    a.type = kTrafficTypes[traffic.size() % std::size(kTrafficTypes)];
    a.path = other;
    a.start_s = s;
    a.speed = kTrafficSpeed;
    traffic.push_back(a);
  }
  return traffic;
}

int64_t lane_scans(const SurveyLane& lane, const MappingOptions& o, const Hdl32eConfig& lidar) {
  return int64_t(lane.path.length / o.speed / (double(lidar.scan_period_ns()) * 1e-9));
}

// The parts of every lane, in the order they are merged. A lane with traffic is one part: its actors
// move in a scene of its own, as the lane's scans go by.
std::vector<DrivePart> plan_parts(const IntensityMapHeader& header, const SurveyDrive& survey, const MappingOptions& o,
                                  const Hdl32eConfig& lidar) {
  // How far from the path a part's points can fall: the range limit from the sensor, the sensor's offset
  // from the rear axle, and the survey error (which moves a point by its position error plus its
  // heading error times its distance).
  double error_xy = 0, error_yaw = 0;
  for (const Pose2d& e : survey.error.samples)
    error_xy = std::max(error_xy, std::hypot(e.x, e.y)), error_yaw = std::max(error_yaw, std::abs(e.yaw));
  const double near = o.max_range + lidar.mount().translation().head<2>().norm();
  const double reach = near + near * error_yaw + error_xy + kReachSlack;
  const double period_s = double(lidar.scan_period_ns()) * 1e-9;
  std::vector<DrivePart> parts;
  for (size_t l = 0; l < survey.lanes.size(); ++l) {
    const Path& path = survey.lanes[l].path;
    const int64_t scans = lane_scans(survey.lanes[l], o, lidar);
    const int64_t step =
        o.traffic && !oncoming_traffic(survey.lanes[l], o).empty() ? std::max<int64_t>(scans, 1) : kPartScans;
    for (int64_t first = 0; first < scans; first += step) {
      DrivePart part{l, first, std::min(scans, first + step), {}, {}};
      // The last scan's firing cycles run on for a scan period.
      const double s0 = o.speed * double(part.first_scan) * period_s, s1 = o.speed * double(part.end_scan) * period_s;
      Eigen::AlignedBox2d box;
      for (double s = s0;; s = std::min(s1, s + kReachStep)) {
        const Pose2d p = path.pose_at(s);
        box.extend(Eigen::Vector2d(p.x, p.y));
        if (s >= s1) break;
      }
      const CellIndex lo = cell_index(header, box.min() - Eigen::Vector2d::Constant(reach));
      const CellIndex hi = cell_index(header, box.max() + Eigen::Vector2d::Constant(reach));
      for (int tx = lo.tile_x; tx <= hi.tile_x; ++tx)
        for (int ty = lo.tile_y; ty <= hi.tile_y; ++ty) part.tiles.push_back({tx, ty});
      const Pose2d mid = path.pose_at((s0 + s1) / 2);
      const CellIndex m = cell_index(header, {mid.x, mid.y});
      part.where = {m.tile_x, m.tile_y};
      parts.push_back(std::move(part));
    }
  }
  // Column by column, row by row: the tiles open at any time are a few columns of the map, not the
  // whole of a long lane's (a ring road's tiles would otherwise wait for the lanes that end on it).
  std::stable_sort(parts.begin(), parts.end(),
                   [](const DrivePart& a, const DrivePart& b) { return a.where < b.where; });
  return parts;
}

// What a part of the drive adds to the map: intensities, and points if the point layer is made.
struct PartMaps {
  IntensityMapBuilder intensity;
  std::optional<PointMapBuilder> points;
};

// The point layer's header: its tiles are the intensity layer's, in whole voxels.
PointMapHeader point_map_header(const IntensityMapHeader& intensity, double voxel_m) {
  constexpr double kWholeVoxels = 1e-9;  // relative
  PointMapHeader h;
  h.world = intensity.world;
  h.world_hash = intensity.world_hash;
  h.voxel_m = voxel_m;
  const double voxels = intensity.tile_size_m() / voxel_m;
  h.tile_voxels = int(std::lround(voxels));
  if (h.tile_voxels < 1 || std::abs(voxels - h.tile_voxels) > kWholeVoxels * voxels)
    throw std::invalid_argument("mapping: the point voxel (" + std::to_string(voxel_m) +
                                " m) must divide the intensity tiles (" + std::to_string(intensity.tile_size_m()) +
                                " m)");
  return h;
}

// One part of a lane, driven into builders of its own (small tiles, made where points fall).
PartMaps drive_part(const DriveSetup& d, const IntensityMapHeader& header, const std::optional<PointMapHeader>& points,
                    const DrivePart& part) {
  IntensityMapHeader part_header = header;
  part_header.tile_cells = kPartTileCells;
  PartMaps maps{IntensityMapBuilder(part_header), {}};
  IntensityMapBuilder& builder = maps.intensity;
  if (points) maps.points.emplace(*points);
  const SurveyLane& lane = d.survey.lanes[part.lane];
  const Path& path = lane.path;
  const MappingOptions& o = d.o;
  const VehicleParams survey_car;
  const int64_t period = d.lidar.scan_period_ns();
  const Eigen::Isometry3d mount = d.lidar.mount();

  // Oncoming traffic on the other side of this road, if asked: a scene of this lane's own, with the
  // survey day's parked cars too (the shared scene has them).
  std::vector<ActorPlan> traffic = oncoming_traffic(lane, o);
  std::unique_ptr<RayScene> own_scene;
  if (!traffic.empty()) {
    own_scene = std::make_unique<RayScene>(d.world.mesh, 0, RayScene::MeshBuffers::shared);
    traffic.insert(traffic.end(), o.parked.begin(), o.parked.end());
    add_actors(*own_scene, traffic, d.actors_dir, d.materials, d.ground);
  }
  RayScene& scene = own_scene ? *own_scene : d.scene;
  const ActorPoses actor_poses = actor_motion(traffic, d.ground);

  // The car is where the truth says, resting on the crowned, rough road; its scans are placed where
  // the survey says: the survey's plan position and heading error moves the whole body.
  // Resting poses every kRestStep along the lane (those of this part); between them the car moves in
  // the plane with the last one's height, pitch and roll (finding them costs four ground lookups, and
  // a scan has 2170 firing cycles).
  const size_t rests = size_t(path.length / kRestStep) + 2;
  auto rest_index = [&](double s) { return std::min(rests - 1, size_t(std::max(0.0, s / kRestStep))); };
  const size_t k0 = rest_index(o.speed * ns_to_s(part.first_scan * period));
  const size_t k1 = rest_index(o.speed * ns_to_s((part.end_scan + 1) * period)) + 1;
  std::vector<Eigen::Isometry3d> rest(std::min(rests, k1 + 1) - k0);
  for (size_t k = 0; k < rest.size(); ++k)
    rest[k] = rest_on_ground(path.pose_at(double(k0 + k) * kRestStep), d.pavement, survey_car.wheelbase(),
                             survey_car.track_width);
  auto resting = [&](int64_t t) {
    const double s = o.speed * ns_to_s(t);
    const size_t k = rest_index(s);
    return to_isometry(path.pose_at(s)) * to_isometry(path.pose_at(double(k) * kRestStep)).inverse() * rest.at(k - k0);
  };
  // The scanner asks for the car's pose at the start of every firing cycle, and the survey places the
  // cycle's points with the same pose: computed once per scan, on that grid.
  const int64_t cycle_ns = d.lidar.cycle_period_ns();
  std::vector<Eigen::Isometry3d> at_cycle(size_t(d.lidar.cycles_per_scan()) + 1);
  int64_t grid_stamp = 0;
  const PoseAt vehicle = [&](int64_t t) {
    const int64_t c = (t - grid_stamp) / cycle_ns;
    if (t >= grid_stamp && c * cycle_ns == t - grid_stamp && size_t(c) < at_cycle.size()) return at_cycle[size_t(c)];
    return resting(t);
  };
  const PoseAt surveyed = [&](int64_t t) {
    const double s = o.speed * ns_to_s(t);
    const Pose2d truth = path.pose_at(s);
    const Eigen::Isometry3d error =
        to_isometry(surveyed_pose(truth, d.survey.error.at(lane.start_m + s))) * to_isometry(truth).inverse();
    return error * vehicle(t);
  };
  for (int64_t k = part.first_scan; k < part.end_scan; ++k) {
    const int64_t stamp = k * period;
    for (size_t c = 0; c < at_cycle.size(); ++c) at_cycle[c] = resting(stamp + int64_t(c) * cycle_ns);
    grid_stamp = stamp;
    PointMapBuilder* const point_layer = maps.points && k % o.point_scan_stride == 0 ? &*maps.points : nullptr;
    // A scan for the point layer keeps every surface; one for the intensity layer only the ground.
    const uint32_t lasers =
        point_layer ? LidarScanner::kAllLasers : ground_lasers(d.lidar, at_cycle, o.max_ground_height);
    const PointCloud cloud = d.scanner.scan(scene, vehicle, stamp, o.seed, actor_poses, nullptr, lasers);
    // The survey places each point with its pose at the point's own firing cycle.
    uint32_t cycle = UINT32_MAX;
    Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
    for (const LidarPoint& p : cloud.points) {
      if (double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z > o.max_range * o.max_range) continue;
      if (p.intensity > 100 && !point_layer) continue;  // a sign or a reflector, not the road surface
      const uint32_t c = uint32_t(p.t_ns / cycle_ns);
      if (c != cycle) cycle = c, body = surveyed(stamp + int64_t(c) * cycle_ns);
      const Eigen::Vector3d w = body * (mount * Eigen::Vector3d(p.x, p.y, p.z));
      if (point_layer) point_layer->add(w);  // every surface: the point layer
      if (p.intensity > 100) continue;
      // Higher than this above the ground under the car, a point cannot be ground. Level, not in the
      // plane of the wheels: on a 2 % crown that plane is 0.4 m off at 20 m across the road.
      if (w.z() - body.translation().z() > o.max_ground_height) continue;
      builder.add(w.head<2>(), p.intensity);
    }
  }
  return maps;
}

// The drive itself: the map's tiles are handed to `finished` as they are finished, if it is given, or
// kept in the builder returned.
IntensityMapBuilder drive(const WorldDescription& description, const World& world, const MaterialTable& materials,
                          const std::string& actors_dir, const MappingOptions& o, const std::string& world_hash,
                          const FinishedTile* finished, const std::function<void(double)>& progress,
                          PointMapWriter* point_writer) {
  IntensityMapHeader header;
  header.world = description.name;
  header.world_hash = world_hash;
  header.build["mapping"] = o.describe();
  header.origin = description.origin;
  header.resolution_m = o.resolution;
  header.tile_cells = o.tile_cells;
  IntensityMapBuilder map(header);
  std::optional<PointMapHeader> point_header;
  std::optional<PointMapBuilder> points;
  if (point_writer) point_header = point_map_header(header, o.point_voxel_m), points.emplace(*point_header);

  // The survey unit, of its own serial, calibrated in situ by the surveyors (no range biases or
  // intensity offsets left, no mixed returns or dropouts modelled), on a dry day: the map is the same
  // whatever the scenario's realism profile and weather.
  Hdl32eConfig lidar = hdl32e_config_for(Realism::ideal);
  lidar.unit_serial = o.survey_unit_serial;
  // Returns beyond the map's range are dropped below: not casting rays beyond it (with a margin of 50
  // times the range noise) saves traversing the far city and modelling returns that are thrown away.
  lidar.max_range_m = std::min(lidar.max_range_m, o.max_range + kCastMargin);
  const LidarScanner scanner(lidar, materials, weather_config_for(Realism::ideal));
  const GroundHeight pavement = world.pavement();
  const SurveyDrive survey = mapping_survey(description, o);
  // The world's mesh outlives the drive: Embree reads it where it is rather than from a copy.
  RayScene scene(world.mesh, 0, RayScene::MeshBuffers::shared);
  const GroundHeight ground = world.ground();
  // The parked cars never move, so the parts can share the scene they stand in (scan() moves nothing).
  if (!o.parked.empty()) add_actors(scene, o.parked, actors_dir, materials, ground);
  const DriveSetup setup{world, materials, actors_dir, o, survey, lidar, scanner, scene, pavement, ground};
  const std::vector<DrivePart> parts = plan_parts(header, survey, o, lidar);

  // Which part is the last to reach each tile: once it is merged, the tile is finished.
  std::map<std::pair<int, int>, size_t> last_part;
  for (size_t i = 0; i < parts.size(); ++i)
    for (const auto& key : parts[i].tiles) last_part[key] = i;
  int64_t total_scans = 0, merged_scans = 0;
  for (const DrivePart& p : parts) total_scans += p.end_scan - p.first_scan;
  auto hand_over = [&](const std::pair<int, int>& key) {
    if (!finished) return;
    std::vector<IntensityMoments> cells = map.take_tile(key);
    if (!cells.empty()) (*finished)(map.header(), key, cells);
    if (!points) return;
    const std::vector<Eigen::Vector3f> tile = points->take_tile(key);
    if (!tile.empty()) point_writer->write_tile(key, tile);
  };

  struct Driven {
    size_t part = 0;
    std::shared_ptr<const PartMaps> maps;
  };
  size_t next = 0;
  tbb::parallel_pipeline(
      size_t(kPartsInFlightPerThread * tbb::this_task_arena::max_concurrency()),
      tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& fc) {
        if (next == parts.size()) fc.stop();
        return next++;
      }) & tbb::make_filter<size_t, Driven>(tbb::filter_mode::parallel, [&](size_t i) {
        return Driven{i, std::make_shared<const PartMaps>(drive_part(setup, header, point_header, parts[i]))};
      }) & tbb::make_filter<Driven, void>(tbb::filter_mode::serial_in_order, [&](const Driven& d) {
        map.merge(d.maps->intensity);
        if (points) points->merge(*d.maps->points);
        const DrivePart& part = parts[d.part];
        for (const auto& key : part.tiles)
          if (last_part.at(key) == d.part) hand_over(key);
        merged_scans += part.end_scan - part.first_scan;
        if (progress) progress(double(merged_scans) / double(std::max<int64_t>(total_scans, 1)));
      }));
  // Tiles no part was expected to reach (none, if the reach above is right) go last, in key order.
  for (const auto& key : std::vector<std::pair<int, int>>(map.header().tiles))
    if (!last_part.count(key)) hand_over(key);
  if (points) {
    for (const auto& key : std::vector<std::pair<int, int>>(points->header().tiles))
      if (!last_part.count(key))
        if (const std::vector<Eigen::Vector3f> tile = points->take_tile(key); !tile.empty())
          point_writer->write_tile(key, tile);
    point_writer->finish(points->header());
  }
  return map;
}

}  // namespace

IntensityMapHeader run_mapping_drive(const WorldDescription& description, const World& world,
                                     const MaterialTable& materials, const std::string& actors_dir,
                                     const MappingOptions& o, const std::string& world_hash,
                                     const FinishedTile& finished, const std::function<void(double)>& progress,
                                     PointMapWriter* points) {
  return drive(description, world, materials, actors_dir, o, world_hash, &finished, progress, points).header();
}

IntensityMapBuilder run_mapping_drive(const WorldDescription& description, const World& world,
                                      const MaterialTable& materials, const std::string& actors_dir,
                                      const MappingOptions& o, const std::string& world_hash,
                                      const std::function<void(double)>& progress) {
  return drive(description, world, materials, actors_dir, o, world_hash, nullptr, progress, nullptr);
}

}  // namespace lidarloop
