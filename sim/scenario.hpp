#pragma once
// A scenario (scenarios/*.yaml): the world, how long, the seed, the ego's route and speed, sensor
// overrides, traffic, faults done to the localizer, the localizer to test and the thresholds it must meet. Loading
// checks syntax, types, ranges and unknown keys (file:line:col); resolving against the world builds the paths and
// checks that they stay on the road network.
#include <optional>
#include <string>
#include <vector>

#include "common/units.hpp"
#include "sim/can_model.hpp"
#include "sim/clocks.hpp"
#include "sim/controller.hpp"
#include "sim/gps_model.hpp"
#include "sim/hdl32e.hpp"
#include "sim/paint_wear.hpp"
#include "sim/path.hpp"
#include "sim/realism.hpp"
#include "sim/sensor_calibration.hpp"
#include "sim/street_use.hpp"
#include "sim/traffic.hpp"
#include "sim/vehicle_body.hpp"
#include "sim/vehicle_model.hpp"
#include "sim/weather.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct PathSpec {
  std::string where;
  enum class Kind { road, waypoints, crosswalk, lanelets, opendrive } kind = Kind::road;
  // kind == road: a lane of a road
  std::string road;
  Lane lane = Lane::right;
  bool backward = false;
  std::optional<double> offset;
  // kind == waypoints
  Polyline2d waypoints;
  double smoothing_radius = 0;
  bool closed = false;
  // kind == crosswalk: across the road at crosswalk number `crosswalk` of the world
  int crosswalk = -1;
  bool from_left = false;
  // kind == lanelets, on a world from a Lanelet2 map (sim/lane_graph.hpp): the lanelets in driving
  // order (`u_turn` between two of them: a U-turn at the end of the one before, before lanelets[i] for
  // each i in u_turns), or the shortest route between two points
  std::vector<int64_t> lanelets;
  std::vector<size_t> u_turns;
  std::optional<Eigen::Vector2d> route_from, route_to;  // on a Lanelet2 or an OpenDRIVE map
  // kind == opendrive, on a world from an OpenDRIVE map (sim/opendrive_lane_graph.hpp): the lanes in
  // driving order, as road id and lane id
  std::vector<std::pair<std::string, int>> opendrive_lanes;
};

struct TrafficSpec {
  std::string where;
  ActorType type = ActorType::car;
  bool parked = false;
  PathSpec path;                   // when moving
  Eigen::Vector2d position{0, 0};  // when parked
  double yaw = 0;                  // when parked, rad
  double start_at = 0;             // arc length on the path at t = 0, m
  double speed = 0;                // m/s
  double depart_s = 0;             // when it starts moving
  std::vector<Wait> waits;
};

struct EgoSpec {
  std::string where;
  PathSpec route;
  double start_at = 0;       // arc length on the route where the rear axle starts, m
  double speed = 10.0;       // cruise speed, m/s
  double initial_speed = 0;  // m/s at t = 0
  std::vector<Wait> stops;   // arc lengths along the route (unwrapped on loops)
  VehicleParams vehicle;
  ControllerParams controller;
};

// The default alert limits (PassThresholds), lateral and longitudinal alike: Reid et al., "Localization
// Requirements for Autonomous Vehicles", SAE Int. J. CAV 2(3):173-190, 2019, derive error bounds
// (alert limits) of 0.29 m (0.10 m at 95 %) for a passenger vehicle on local streets, the roads the
// suite drives (0.57 m lateral, 1.40 m longitudinal on freeways).
constexpr double kLocalStreetAlertLimit_m = 0.29;

struct PassThresholds {
  std::optional<double> lateral_rmse_m, longitudinal_rmse_m, heading_rmse_deg, max_position_error_m;
  // How far the car's true rear axle may stray from its lane's centre (closed loop: the controller
  // steers on the estimate, so a localizer error becomes a driving error).
  std::optional<double> max_lane_offset_m;
  // Estimates in the first settle_s seconds (from the first estimate) are not scored: the localizer
  // starts from one GPS fix that may be metres off, and its convergence is not its accuracy.
  double settle_s = 0;
  // The least share of the truth's time span the estimates must cover (scoring/scorer.hpp's coverage):
  // an estimate that starts late, stops early or has gaps is scored on what exists, and this says
  // how much must exist.
  std::optional<double> min_coverage;
  // Integrity and consistency (scoring/scorer.hpp defines each figure). The alert limits are what a
  // protection bound must stay under for its frame to count as available.
  std::optional<double> max_misleading_fraction, min_availability;
  double alert_limit_lateral_m = kLocalStreetAlertLimit_m, alert_limit_longitudinal_m = kLocalStreetAlertLimit_m;
  // Each axis' mean NEES must lie within [min_mean_nees, max_mean_nees] when set.
  std::optional<double> min_mean_nees, max_mean_nees;
  // Recovery from the run's start and its faults (loop/fault_events.hpp): `position_m` is the error
  // a recovered estimate stays under; when set, every event must recover within `within_s` and every
  // fault raise `lost` within `lost_within_s` and clear it before the next event, and the frames
  // within `within_s` after a fault are kept out of the accuracy metrics. Unset, the defaults still
  // define the recovery figures reported.
  struct Recovery {
    // The suite's goal for its cold-start and fault scenarios: under 0.3 m within 3 s of the start or
    // the fault, `lost` raised within 1 s of the fault.
    double position_m = 0.3, within_s = 3.0, lost_within_s = 1.0;
  };
  std::optional<Recovery> recovery;
  // `against: reference`: the four accuracy thresholds above (the RMSEs and the worst position error)
  // are checked against the run's reference (ReferenceConfig) rather than the exact truth, as a real
  // experiment can only check them. Everything else (lane offset, coverage, NEES, integrity, recovery)
  // stays on the truth. Default `truth`: the simulator knows the truth, so it judges by it.
  bool against_reference = false;
};

// The reference trajectory a run is scored against beside the exact truth (`reference`): what a real
// experiment scores against, the pose of an RTK-INS reference system, itself a few centimetres off
// (scoring/reference_trajectory.hpp draws it from the truth). Its error on each map axis and on the
// heading is a first-order Gauss-Markov process with the stationary 1 sigma and correlation time below,
// as (D)GPS error is usually modelled (Rankin, "An error model for sensor simulation GPS and
// differential GPS", IEEE PLANS 1994; sim/gps_model.hpp models the receiver the same way).
//
// The paper's reference: "All reference positions of the vehicle is acquired by the real-time
// kinematic (RTK) GPS, which has an average accuracy of 3 cm" (its Section 4.1). Read, as sim/gps_model's
// RtkConfig reads it, as 3 cm 1 sigma per horizontal axis: the upper end of what RTK-INS reference systems
// state (OxTS RT3000 and Applanix POS LV datasheets: 1-2 cm with RTK).
constexpr double kRtkReferenceSigma_m = 0.03;
// RTK-INS reference systems state 0.03-0.1 deg heading, 1 sigma (OxTS RT3000, Applanix POS LV); the
// paper states none, so its conservative end, as for the position.
constexpr double kRtkReferenceHeadingSigma_deg = 0.1;
// Assumption: RTK's residual errors (carrier multipath, what is left of the atmosphere between base and
// rover) stay correlated for tens of seconds on a moving car; 30 s sits in that range. A white error
// would average out of an RMSE over a drive; a correlated one does not, so it matters which.
constexpr double kRtkReferenceCorrelation_s = 30.0;

struct ReferenceConfig {
  // none: scored against the truth only (the `ideal` profile); rtk: also against an RTK-INS reference.
  enum class Kind { none, rtk };
  Kind kind = Kind::rtk;
  double sigma_xy_m = kRtkReferenceSigma_m;  // per map axis (east, north), stationary 1 sigma
  double heading_sigma_rad = kRtkReferenceHeadingSigma_deg * kDeg;
  double correlation_s = kRtkReferenceCorrelation_s;  // of every axis' error
};
// ideal: none (the simulator before realism scores against the truth it knows); typical and harsh: the
// paper's RTK reference above. `harsh` degrades the map, the weather and the sensor, not the reference
// system a real experiment would score against; a worse reference is a scenario's to set.
ReferenceConfig reference_config_for(Realism realism);
// "rtk" or "none".
const char* reference_kind_name(ReferenceConfig::Kind kind);

// Thresholds given apart from a scenario (`lidarloop score`), read as strictly as a scenario's
// `pass`, each over `base` (keys present replace base's values):
// a YAML file holding only a `pass:` mapping; InputError "file:line:col: ..." for anything else.
PassThresholds load_pass_file(const std::string& path, const PassThresholds& base);
// "key=value" with a key of `pass`; InputError naming `what` (e.g. "--threshold") and the problem.
PassThresholds parse_pass_assignment(const std::string& assignment, const std::string& what,
                                     const PassThresholds& base);

// A kidnapped robot (`faults:`): at at_s the localizer's belief and the car part by `offset` (m,
// forward and left in the vehicle frame) and a turn by yaw, and nothing tells the localizer.
//   belief  its pose estimate is moved, its covariance left as it was; the car and the world go on as
//           before. Only a built-in localizer's belief can be moved (loop/kidnap_schedule.hpp).
//   car     the car itself is lifted and set down there between two scans, its speed, steering and
//           suspension as they were; its wheels do not turn on the way, so the CAN does not see it.
//           Every method meets it, an outside program too; the car steers back to its route after.
enum class KidnapMoves { belief, car };
struct KidnapFault {
  double at_s = 0;
  Eigen::Vector2d offset_m{0, 0};
  double yaw_rad = 0;
  KidnapMoves moves = KidnapMoves::belief;
};
// The scan start a kidnap is done at, on the simulation's clock: the nearest its time, from half a scan
// period before it (so a scan that starts exactly at at_s takes it).
int64_t kidnap_scan_start_ns(const KidnapFault& kidnap, int64_t scan_period_ns);

struct Scenario {
  std::string file;
  std::string text;              // the YAML as read: recorded with logs, re-read for `localizer`
  std::string world = "campus";  // a name under maps/ or a path
  double duration_s = 60;
  uint64_t seed = 1;
  // Selects the defaults of every realism knob below; the sections override them (sim/realism.hpp).
  Realism realism = Realism::typical;
  EgoSpec ego;
  Hdl32eConfig lidar;
  CanConfig can;
  GpsConfig gps;
  RtkConfig rtk;
  BodyConfig body;               // the ego's suspension (`body`)
  WeatherConfig weather;         // the day the scenario is driven on (the map was surveyed on a dry one)
  PaintConfig paint;             // the markings' wear, on the survey day and today (`paint`)
  MountErrorConfig mount_error;  // the true LiDAR mount and GPS antenna against the nominal `lidar` / `gps` ones
  ClockConfig clocks;            // the LiDAR's and the CAN's stamping clocks against the reference
  std::vector<TrafficSpec> traffic;
  StreetUse street;                  // the actors the street's use brings (`street`), after `traffic`'s
  std::vector<KidnapFault> kidnaps;  // `faults:` entries of kind kidnap
  // `localizer`: the method here; the rest of the section (parameter overrides) belongs to the
  // localizer and is read by the tools from `text`, since sim/ does not know the localizer.
  std::string localizer_method = "proposed";
  bool closed_loop = false;
  PassThresholds pass;
  ReferenceConfig reference;  // what the run is scored against beside the truth (`reference`)
  int scan_every = 10;        // simulate: write every Nth scan as PLY

  int64_t duration_ns() const { return static_cast<int64_t>(duration_s * 1e9 + 0.5); }
};

// `vehicle`: the ego's parameters before the scenario's own overrides (assets/vehicle.yaml).
// `realism`: a profile that replaces the scenario's own (a command's --realism); the sections' overrides
// still apply on top of it.
Scenario load_scenario(const std::string& path, const VehicleParams& vehicle = {},
                       std::optional<Realism> realism = std::nullopt);
Scenario parse_scenario(const std::string& yaml_text, const std::string& name, const VehicleParams& vehicle = {},
                        std::optional<Realism> realism = std::nullopt);

// The realism knobs the scenario sets itself, on top of its profile: every scalar under the sections
// that hold knobs (lidar, body, weather, paint, clocks, mount_error, can, gps, rtk, survey, world_changes,
// reference), as "section.key = value" in file order, so a report can say how a run differs from its profile.
std::vector<std::string> realism_overrides(const Scenario& scenario);

struct ResolvedScenario {
  Path ego_route;
  std::vector<ActorPlan> actors;
};
// Builds every path on `world` and checks it: vehicles stay on the carriageway, pedestrians and
// cyclists on the carriageway or sidewalks. InputError names the scenario entry's file:line:col.
ResolvedScenario resolve_scenario(const Scenario& scenario, const WorldDescription& description, const World& world);

}  // namespace lidarloop
