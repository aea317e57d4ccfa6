#include "sim/scenario.hpp"

#include <cmath>
#include <limits>

#include "common/input_error.hpp"
#include "common/localizer_method.hpp"
#include "common/path_beside.hpp"
#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "sim/lane_graph.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/region.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

constexpr double kMaxDuration = 24 * 3600;  // s
constexpr double kMaxSpeed = 40;            // m/s for any actor
constexpr double kPathCheckStep = 1.0;      // m between on-road checks
constexpr double kMaxAlertLimit = 1e4;      // m, as the other distance thresholds of `pass`
constexpr double kMaxNees = 1e6;            // a mean NEES bound beyond any filter worth gating
// A reference is centimetres off; a metre (or 10 deg) is no reference but a second localizer to score.
constexpr double kMaxReferenceSigma_m = 1.0, kMaxReferenceHeadingSigma_deg = 10.0;
// Below a truth sample's 10 ms every sample's error would be drawn afresh: white, not correlated.
constexpr double kMinReferenceCorrelation_s = 0.01;

std::vector<Wait> read_waits(const YamlReader& y, const YAML::Node& n, const char* what) {
  std::vector<Wait> out;
  if (!n) return out;
  y.expect_sequence(n, what);
  for (const auto& w : n) {
    YamlMap m(y, w, std::string("an entry of ") + what);
    out.push_back({y.number_in(m.required("at"), "at", 0.0, 1e6),
                   y.number_in(m.required("duration_s"), "duration_s", 0.0, kMaxDuration)});
    m.done();
  }
  std::sort(out.begin(), out.end(), [](const Wait& a, const Wait& b) { return a.at < b.at; });
  return out;
}

bool read_choice(const YamlReader& y, const YAML::Node& n, const std::string& what, const char* no, const char* yes);

// A `pass` mapping over the values `pass` already holds.
void read_pass(const YamlReader& y, const YAML::Node& n, PassThresholds& pass) {
  YamlMap m(y, n, "pass");
  m.number("lateral_rmse_m", pass.lateral_rmse_m, 0.0, 1e4)
      .number("longitudinal_rmse_m", pass.longitudinal_rmse_m, 0.0, 1e4)
      .number("heading_rmse_deg", pass.heading_rmse_deg, 0.0, 1e4)
      .number("max_position_error_m", pass.max_position_error_m, 0.0, 1e4)
      .number("max_lane_offset_m", pass.max_lane_offset_m, 0.0, 1e4)
      .number("settle_s", pass.settle_s, 0.0, 60.0)
      .number("min_coverage", pass.min_coverage, 0.0, 1.0)
      .number("max_misleading_fraction", pass.max_misleading_fraction, 0.0, 1.0)
      .number("min_availability", pass.min_availability, 0.0, 1.0)
      .number("alert_limit_lateral_m", pass.alert_limit_lateral_m, 0.0, kMaxAlertLimit)
      .number("alert_limit_longitudinal_m", pass.alert_limit_longitudinal_m, 0.0, kMaxAlertLimit)
      .number("min_mean_nees", pass.min_mean_nees, 0.0, kMaxNees)
      .number("max_mean_nees", pass.max_mean_nees, 0.0, kMaxNees);
  if (const YAML::Node against = m["against"])
    pass.against_reference = read_choice(y, against, "against", "truth", "reference");
  if (const YAML::Node r = m["recovery"]) {
    PassThresholds::Recovery recovery = pass.recovery.value_or(PassThresholds::Recovery{});
    YamlMap(y, r, "recovery")
        .number("position_m", recovery.position_m, 0.0, kMaxAlertLimit)
        .number("within_s", recovery.within_s, 0.0, kMaxDuration)
        .number("lost_within_s", recovery.lost_within_s, 0.0, kMaxDuration)
        .done();
    pass.recovery = recovery;
  }
  m.done();
  if (pass.min_mean_nees && pass.max_mean_nees && *pass.min_mean_nees > *pass.max_mean_nees)
    y.fail(m["min_mean_nees"] ? m["min_mean_nees"] : m["max_mean_nees"], "min_mean_nees is above max_mean_nees");
}

// One of two words, as a bool: true for `yes`.
bool read_choice(const YamlReader& y, const YAML::Node& n, const std::string& what, const char* no, const char* yes) {
  const std::string word = y.string(n, what);
  if (word != no && word != yes) y.fail(n, what + " must be " + no + " or " + yes + ", got '" + word + "'");
  return word == yes;
}

PathSpec read_path(const YamlReader& y, const YAML::Node& n, const char* what) {
  YamlMap m(y, n, what);
  PathSpec p;
  p.where = m.where();
  const YAML::Node road = m["road"], waypoints = m["waypoints"], crosswalk = m["crosswalk"];
  // On a Lanelet2 map: the lanelets to drive; on an OpenDRIVE map its lanes; on either a place to drive
  // to (from `from`).
  const YAML::Node lanelets = m["lanelets"], opendrive = m["opendrive"], to = m["to"];
  if (int(bool(road)) + int(bool(waypoints)) + int(bool(crosswalk)) + int(bool(lanelets)) + int(bool(opendrive)) +
          int(bool(to)) !=
      1)
    y.fail(n, std::string(what) +
                  " needs exactly one of 'road', 'waypoints', 'crosswalk', 'lanelets', 'opendrive' or 'from' and 'to'");
  const YAML::Node lane = m["lane"], direction = m["direction"], offset = m["offset"];
  if (road) {
    p.kind = PathSpec::Kind::road;
    p.road = y.string(road, "road");
    if (lane) p.lane = read_choice(y, lane, "lane", "right", "left") ? Lane::left : Lane::right;
    if (direction) p.backward = read_choice(y, direction, "direction", "forward", "backward");
    if (offset) p.offset = y.number_in(offset, "offset", -30.0, 30.0);
  } else {
    for (const char* key : {"lane", "direction", "offset"})
      if (n[key]) y.fail(n[key], std::string(key) + " applies only to a road path");
  }
  if (waypoints) {
    p.kind = PathSpec::Kind::waypoints;
    y.expect_sequence(waypoints, "waypoints");
    for (const auto& w : waypoints) p.waypoints.push_back(y.vec2(w, "a waypoint"));
    if (p.waypoints.size() < 2) y.fail(waypoints, "a path needs at least 2 waypoints");
    for (size_t i = 1; i < p.waypoints.size(); ++i)
      if ((p.waypoints[i] - p.waypoints[i - 1]).norm() < 0.01) y.fail(waypoints[i], "repeated waypoint");
    m.number("smoothing_radius", p.smoothing_radius, 0.0, 500.0).boolean("closed", p.closed);
  }
  if (lanelets) {
    p.kind = PathSpec::Kind::lanelets;
    y.expect_sequence(lanelets, "lanelets");
    for (const auto& id : lanelets) {
      if (id.IsScalar() && id.Scalar() == "u_turn") {
        if (p.lanelets.empty() || (!p.u_turns.empty() && p.u_turns.back() == p.lanelets.size()))
          y.fail(id, "a U-turn must come between two lanelets");
        p.u_turns.push_back(p.lanelets.size());
        continue;
      }
      p.lanelets.push_back(y.integer_in(id, "a lanelet id (or u_turn)", std::numeric_limits<long>::min(),
                                        std::numeric_limits<long>::max()));
    }
    if (p.lanelets.empty()) y.fail(lanelets, "a route needs at least one lanelet");
    if (!p.u_turns.empty() && p.u_turns.back() == p.lanelets.size())
      y.fail(lanelets, "a U-turn must come between two lanelets, not at the end");
  }
  if (opendrive) {
    p.kind = PathSpec::Kind::opendrive;
    y.expect_sequence(opendrive, "opendrive");
    for (const auto& lane : opendrive) {
      y.expect_sequence(lane, "a lane [road, lane]");
      if (lane.size() != 2) y.fail(lane, "a lane is [road id, lane id]");
      p.opendrive_lanes.emplace_back(y.string(lane[0], "a road id"),
                                     int(y.integer_in(lane[1], "a lane id", -100, 100)));
    }
    if (p.opendrive_lanes.empty()) y.fail(opendrive, "a route needs at least one lane");
  }
  if (to) {
    p.kind = PathSpec::Kind::lanelets;
    p.route_from = y.vec2(m.required("from"), "from");
    p.route_to = y.vec2(to, "to");
  }
  if (crosswalk) {
    p.kind = PathSpec::Kind::crosswalk;
    p.crosswalk = int(y.integer_in(crosswalk, "crosswalk", 0, 10000));
    if (const YAML::Node from = m["from"]) p.from_left = read_choice(y, from, "from", "right", "left");
  }
  m.done();
  return p;
}

void read_can(const YamlReader& y, const YAML::Node& n, CanConfig& c) {
  YamlMap m(y, n, "can");
  m.number("rate_hz", c.rate_hz, 1.0, 1000.0)
      .number("wheel_speed_resolution_mps", c.wheel_speed_resolution_mps, 0.0, 1.0)
      .number("wheel_speed_noise_mps", c.wheel_speed_noise_mps, 0.0, 5.0)
      .number("wheel_speed_scale_error", c.wheel_speed_scale_error, -0.2, 0.2)
      .number("min_detectable_speed_mps", c.min_detectable_speed_mps, 0.0, 2.0)
      .number("steering_resolution_rad", c.steering_resolution_rad, 0.0, 0.1)
      .number("steering_noise_rad", c.steering_noise_rad, 0.0, 0.5)
      .number("steering_offset_rad", c.steering_offset_rad, -0.5, 0.5)
      .number("dropout_probability", c.dropout_probability, 0.0, 0.99);
  if (const YAML::Node l = m["latency_ms"])
    c.latency_ns = std::llround(y.number_in(l, "latency_ms", 0.0, 1000.0) * 1e6);
  m.done();
}

GpsZone read_gps_zone(const YamlReader& y, const YAML::Node& z) {
  YamlMap m(y, z, "a GPS zone");
  GpsZone zone;
  const YAML::Node kind = m.required("kind");
  zone.kind =
      read_choice(y, kind, "zone kind", "outage", "multipath") ? GpsZone::Kind::multipath : GpsZone::Kind::outage;
  const YAML::Node centre = m["centre"], radius = m["radius"], from = m["from_s"], to = m["to_s"], jump = m["jump"];
  if (centre) zone.centre = y.vec2(centre, "centre");
  if (radius) zone.radius_m = y.number_in(radius, "radius", 0.1, 1e5);
  if (bool(centre) != bool(radius)) y.fail(z, "a zone's centre and radius go together");
  if (from) zone.from_ns = int64_t(y.number_in(from, "from_s", 0.0, kMaxDuration) * 1e9);
  if (to) zone.to_ns = int64_t(y.number_in(to, "to_s", 0.0, kMaxDuration) * 1e9);
  if (zone.to_ns <= zone.from_ns) y.fail(z, "a zone's to_s must be after its from_s");
  if (!centre && !from && !to) y.fail(z, "a zone needs a centre and radius, or from_s/to_s");
  if (zone.kind == GpsZone::Kind::multipath)
    zone.jump_m = y.vec2(m.required("jump"), "jump");
  else if (jump)
    y.fail(jump, "jump applies only to multipath zones");
  m.done();
  return zone;
}

void read_gps(const YamlReader& y, const YAML::Node& n, GpsConfig& g) {
  YamlMap m(y, n, "gps");
  m.number("rate_hz", g.rate_hz, 0.1, 100.0)
      .number("bias_sigma_m", g.bias_sigma_m, 0.0, 100.0)
      .number("bias_tau_s", g.bias_tau_s, 0.1, 1e5)
      .number("white_sigma_m", g.white_sigma_m, 0.0, 100.0)
      .number("vertical_sigma_m", g.vertical_sigma_m, 0.0, 100.0)
      .degrees("heading_bias_sigma_deg", g.heading_bias_sigma_rad, 0.0, 90.0)
      .number("heading_bias_tau_s", g.heading_bias_tau_s, 0.1, 1e5)
      .degrees("heading_white_sigma_deg", g.heading_white_sigma_rad, 0.0, 90.0)
      .vec3("antenna_xyz", g.antenna_xyz);
  if (const YAML::Node zones = m["zones"]) {
    y.expect_sequence(zones, "zones");
    for (const auto& z : zones) g.zones.push_back(read_gps_zone(y, z));
  }
  m.done();
}

void read_rtk(const YamlReader& y, const YAML::Node& n, RtkConfig& r) {
  YamlMap(y, n, "rtk")
      .number("rate_hz", r.rate_hz, 0.1, 100.0)
      .number("sigma_m", r.sigma_m, 0.0, 1.0)
      .degrees("heading_sigma_deg", r.heading_sigma_rad, 0.0, 10.0)
      .done();
}

// `reference`: over the profile's. A knob without a reference to apply it to is a mistake, not a no-op.
void read_reference(const YamlReader& y, const YAML::Node& n, ReferenceConfig& r) {
  YamlMap m(y, n, "reference");
  if (const YAML::Node kind = m["kind"])
    r.kind = read_choice(y, kind, "reference kind", "none", "rtk") ? ReferenceConfig::Kind::rtk
                                                                   : ReferenceConfig::Kind::none;
  m.number("sigma_xy_m", r.sigma_xy_m, 0.0, kMaxReferenceSigma_m)
      .degrees("heading_sigma_deg", r.heading_sigma_rad, 0.0, kMaxReferenceHeadingSigma_deg)
      .number("correlation_s", r.correlation_s, kMinReferenceCorrelation_s, kMaxDuration);
  m.done();
  if (r.kind == ReferenceConfig::Kind::none)
    for (const char* key : {"sigma_xy_m", "heading_sigma_deg", "correlation_s"})
      if (n[key]) y.fail(n[key], std::string(key) + " needs a reference: kind is none (give kind: rtk)");
}

EgoSpec read_ego(const YamlReader& y, const YAML::Node& n, const VehicleParams& vehicle) {
  YamlMap m(y, n, "ego");
  EgoSpec e;
  e.vehicle = vehicle;
  e.where = m.where();
  e.route = read_path(y, m.required("route"), "route");
  if (e.route.kind == PathSpec::Kind::crosswalk) y.fail(n["route"], "the ego cannot drive along a crosswalk");
  m.number("start_at", e.start_at, 0.0, 1e6)
      .number("speed", e.speed, 0.5, kMaxSpeed)
      .number("initial_speed", e.initial_speed, 0.0, kMaxSpeed);
  e.stops = read_waits(y, m["stops"], "stops");
  if (const YAML::Node v = m["vehicle"]) read_vehicle_params(y, v, e.vehicle);
  if (e.speed > e.vehicle.max_speed) y.fail(n["speed"], "speed is above the vehicle's max_speed");
  YamlMap(y, m["controller"], "controller")
      .number("stanley_gain", e.controller.stanley_gain, 0.0, 20.0)
      .number("heading_gain", e.controller.heading_gain, 0.0, 5.0)
      .number("preview_s", e.controller.preview_s, 0.0, 2.0)
      .number("max_lateral_accel", e.controller.max_lateral_accel, 0.5, 8.0)
      .number("comfort_decel", e.controller.comfort_decel, 0.5, 8.0)
      .boolean("dead_reckoning", e.controller.dead_reckoning)
      .done();
  m.done();
  return e;
}

TrafficSpec read_actor(const YamlReader& y, const YAML::Node& n) {
  YamlMap m(y, n, "a traffic actor");
  TrafficSpec a;
  a.where = m.where();
  const YAML::Node type = m.required("type");
  const auto t = actor_type_from_name(y.string(type, "type"));
  if (!t) y.fail(type, "unknown actor type '" + type.Scalar() + "' (expected one of: " + actor_type_names() + ")");
  a.type = *t;
  m.boolean("parked", a.parked);
  if (a.parked) {
    a.position = y.vec2(m.required("position"), "position");
    m.degrees("yaw_deg", a.yaw, -360.0, 360.0);
    for (const char* key : {"path", "speed", "depart_s", "waits", "start_at"})
      if (m[key]) y.fail(n[key], std::string(key) + " makes no sense for a parked actor");
  } else {
    for (const char* key : {"position", "yaw_deg"})
      if (m[key]) y.fail(n[key], std::string(key) + " is for parked actors; a moving one follows its path");
    a.path = read_path(y, m.required("path"), "path");
    a.speed = y.number_in(m.required("speed"), "speed", 0.0, kMaxSpeed);
    m.number("start_at", a.start_at, 0.0, 1e6).number("depart_s", a.depart_s, 0.0, kMaxDuration);
    a.waits = read_waits(y, m["waits"], "waits");
  }
  m.done();
  return a;
}

// A `faults` entry. Kidnaps are the only kind: a GPS jump is the world's doing, a multipath zone of
// `gps`. `duration_s` bounds at_s: a fault after the end would never happen, which is a mistake.
KidnapFault read_fault(const YamlReader& y, const YAML::Node& n, double duration_s) {
  YamlMap m(y, n, "a fault");
  const YAML::Node kind = m.required("kind");
  const std::string word = y.string(kind, "kind");
  if (word != "kidnap")
    y.fail(kind, "unknown fault kind '" + word + "' (expected kidnap; a GPS jump is a multipath zone of gps)");
  KidnapFault f;
  f.at_s = y.number_in(m.required("at_s"), "at_s", 0.0, duration_s);
  f.offset_m = y.vec2(m.required("offset"), "offset");
  m.degrees("yaw_deg", f.yaw_rad, -180.0, 180.0);
  if (const YAML::Node moves = m["moves"])
    f.moves = read_choice(y, moves, "moves", "belief", "car") ? KidnapMoves::car : KidnapMoves::belief;
  m.done();
  return f;
}

Scenario parse(const YamlReader& y, const VehicleParams& vehicle, std::optional<Realism> realism) {
  YamlMap root(y, y.root(), "a scenario");
  Scenario s;
  s.file = y.file();
  s.text = y.text();
  s.world = y.string(root.required("world"), "world");
  s.duration_s = y.number_in(root.required("duration_s"), "duration_s", 0.1, kMaxDuration);
  root.integer("seed", s.seed, 0, uint64_t(1) << 62);
  // The profile first: it sets the defaults that the sections below override.
  if (const YAML::Node r = root["realism"]) {
    const std::string word = y.string(r, "realism");
    const std::optional<Realism> profile = parse_realism(word);
    if (!profile) y.fail(r, "realism must be ideal, typical or harsh, got '" + word + "'");
    s.realism = *profile;
  }
  if (realism) s.realism = *realism;
  s.ego = read_ego(y, root.required("ego"), vehicle);
  s.lidar = hdl32e_config_for(s.realism);
  if (const YAML::Node n = root["lidar"]) read_hdl32e_config(y, n, s.lidar);
  if (const YAML::Node n = root["can"]) read_can(y, n, s.can);
  s.gps = gps_config_for(s.realism);
  if (const YAML::Node n = root["gps"]) read_gps(y, n, s.gps);
  if (const YAML::Node n = root["rtk"]) read_rtk(y, n, s.rtk);
  s.body = body_config_for(s.realism);
  read_body_config(y, root["body"], s.body);
  s.weather = weather_config_for(s.realism);
  if (const YAML::Node n = root["weather"]) read_weather_config(y, n, s.weather);
  s.paint = paint_config_for(s.realism);
  if (const YAML::Node n = root["paint"]) read_paint_config(y, n, s.paint);
  s.mount_error = mount_error_config_for(s.realism);
  read_mount_error(y, root["mount_error"], s.mount_error);
  s.clocks = clock_config_for(s.realism);
  read_clocks(y, root["clocks"], s.clocks);
  if (const YAML::Node t = root["traffic"]) {
    y.expect_sequence(t, "traffic");
    for (const auto& a : t) s.traffic.push_back(read_actor(y, a));
  }
  if (const YAML::Node n = root["street"]) read_street_use(y, n, s.street);
  if (const YAML::Node faults = root["faults"]) {
    y.expect_sequence(faults, "faults");
    for (const auto& f : faults) s.kidnaps.push_back(read_fault(y, f, s.duration_s));
  }
  // The localizer section is the localizer's to check (read_localizer_params); the method is read
  // here too because the scenario names it in its outputs.
  if (const YAML::Node l = root["localizer"]) {
    y.expect_map(l, "localizer");
    if (l["method"]) {
      s.localizer_method = y.string(l["method"], "method");
      try {
        parse_localizer_method(s.localizer_method);
      } catch (const std::invalid_argument& e) {
        y.fail(l["method"], e.what());
      }
    }
  }
  // How today's world differs from the surveyed one: applied, and checked, with the world
  // (load_scenario_world), since its positions refer to the world's roads.
  if (const YAML::Node changes = root["world_changes"]) y.expect_map(changes, "world_changes");
  // The map's survey settings (mapping/mapping_drive.hpp's read_survey_options), read with the map.
  if (const YAML::Node survey = root["survey"]) y.expect_map(survey, "survey");
  if (const YAML::Node loop = root["loop"]) s.closed_loop = read_choice(y, loop, "loop", "open", "closed");
  s.reference = reference_config_for(s.realism);
  if (const YAML::Node n = root["reference"]) read_reference(y, n, s.reference);
  read_pass(y, root["pass"], s.pass);
  if (s.pass.against_reference && s.reference.kind == ReferenceConfig::Kind::none)
    y.fail(root["pass"]["against"], "pass against the reference, but the scenario has none (reference kind none)");
  YamlMap(y, root["output"], "output").integer("scan_every", s.scan_every, 0, 1000000).done();
  root.done();
  return s;
}

// A built path, and where its U-turns leave the lanelets (their loops run beyond the map's lanes).
struct BuiltPath {
  Path path;
  std::vector<Eigen::Vector2d> u_turns;
};

BuiltPath build_path(const PathSpec& p, const WorldDescription& d) {
  switch (p.kind) {
    case PathSpec::Kind::road: {
      const RoadSpec* road = d.road(p.road);
      if (!road) throw InputError(p.where + ": unknown road '" + p.road + "' in world '" + d.name + "'");
      return BuiltPath{lane_path(*road, p.lane, p.backward, p.offset ? &*p.offset : nullptr), {}};
    }
    case PathSpec::Kind::waypoints: {
      Polyline2d corners = p.waypoints;
      if (p.closed && (corners.front() - corners.back()).norm() < 0.01) corners.pop_back();
      return BuiltPath{make_path(fillet_polyline(corners, p.smoothing_radius, p.closed, 3 * kDeg), p.closed), {}};
    }
    case PathSpec::Kind::opendrive:
      if (!d.opendrive)
        throw InputError(p.where + ": a route by OpenDRIVE lanes needs a world from an OpenDRIVE map; world '" +
                         d.name + "' has none");
      try {
        const LaneGraph& graph = d.opendrive->graph.graph;
        return BuiltPath{
            make_path(route_centreline(graph, route_from_opendrive_lanes(d.opendrive->graph, p.opendrive_lanes)),
                      false),
            {}};
      } catch (const InputError& e) {
        throw InputError(p.where + ": " + e.what());
      }
    case PathSpec::Kind::lanelets: {
      if (d.opendrive && p.route_to) {
        try {
          const LaneGraph& graph = d.opendrive->graph.graph;
          return BuiltPath{make_path(route_centreline(graph, shortest_route(graph, *p.route_from, *p.route_to)), false),
                           {}};
        } catch (const InputError& e) {
          throw InputError(p.where + ": " + e.what());
        }
      }
      if (!d.lanelet2)
        throw InputError(p.where + ": a route by lanelets needs a world from a Lanelet2 map; world '" + d.name +
                         "' has roads");
      const LaneGraph& graph = d.lanelet2->graph;
      try {
        const std::vector<LaneGraphNodeId> route = p.route_to ? shortest_route(graph, *p.route_from, *p.route_to)
                                                              : route_from_lanelets(graph, p.lanelets, p.u_turns);
        BuiltPath built{make_path(route_driven_line(graph, route), false), {}};
        for (size_t i = 1; i < route.size(); ++i)
          if (route[i] == kUTurn) built.u_turns.push_back(graph.nodes[route[i - 1]].centreline.back());
        return built;
      } catch (const InputError& e) {
        throw InputError(p.where + ": " + e.what());
      }
    }
    case PathSpec::Kind::crosswalk: {
      if (p.crosswalk >= int(d.crosswalks.size()))
        throw InputError(p.where + ": world '" + d.name + "' has " + std::to_string(d.crosswalks.size()) +
                         " crosswalks; there is no crosswalk " + std::to_string(p.crosswalk));
      const CrosswalkSpec& c = d.crosswalks[size_t(p.crosswalk)];
      return BuiltPath{crosswalk_path(*d.road(c.road), c, p.from_left), {}};
    }
  }
  return {};
}

void check_on_network(const BuiltPath& built, const region::Paths& area, const std::string& where, const char* what) {
  const Path& path = built.path;
  // A U-turn's loop reaches about 2.7 radii ahead of where it leaves the lanelets and 1.5 to each side.
  const double loop_reach = 3 * RouteLineOptions{}.u_turn_radius;
  const auto in_a_u_turn = [&](const Eigen::Vector2d& p) {
    return std::any_of(built.u_turns.begin(), built.u_turns.end(),
                       [&](const Eigen::Vector2d& u) { return (p - u).norm() < loop_reach; });
  };
  for (double s = 0; s <= path.length; s += kPathCheckStep) {
    const Pose2d p = path.pose_at(s);
    if (!region::contains(area, {p.x, p.y}) && !in_a_u_turn({p.x, p.y}))
      throw InputError(where + ": " + what + " leaves the road network at (" + std::to_string(int(std::lround(p.x))) +
                       ", " + std::to_string(int(std::lround(p.y))) + "), " + std::to_string(int(s)) + " m along it");
  }
}

}  // namespace

ReferenceConfig reference_config_for(Realism realism) {
  ReferenceConfig r;
  if (realism == Realism::ideal) r.kind = ReferenceConfig::Kind::none;
  return r;
}

const char* reference_kind_name(ReferenceConfig::Kind kind) {
  return kind == ReferenceConfig::Kind::rtk ? "rtk" : "none";
}

Scenario load_scenario(const std::string& path, const VehicleParams& vehicle, std::optional<Realism> realism) {
  Scenario s = parse(YamlReader::open(path), vehicle, realism);
  // A world given as a file is found beside the scenario, from whatever folder lidarloop runs in; a
  // world's name (maps/<name>/) stays a name.
  if (names_a_world_file(s.world)) s.world = path_beside(path, s.world);
  return s;
}
Scenario parse_scenario(const std::string& yaml_text, const std::string& name, const VehicleParams& vehicle,
                        std::optional<Realism> realism) {
  return parse(YamlReader::from_string(yaml_text, name), vehicle, realism);
}

PassThresholds load_pass_file(const std::string& path, const PassThresholds& base) {
  const YamlReader y = YamlReader::open(path);
  YamlMap root(y, y.root(), "the file");
  PassThresholds pass = base;
  read_pass(y, root.required("pass"), pass);
  root.done();
  return pass;
}

PassThresholds parse_pass_assignment(const std::string& assignment, const std::string& what,
                                     const PassThresholds& base) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size())
    throw InputError(what + ": expected KEY=VALUE (a key of a scenario's pass), got '" + assignment + "'");
  // Read as the one-key mapping it stands for, so the keys, types and ranges are checked exactly as
  // in a scenario; the error then points into "KEY: VALUE" (line 1), which is the argument itself.
  const YamlReader y =
      YamlReader::from_string(assignment.substr(0, eq) + ": " + assignment.substr(eq + 1), what + " " + assignment);
  PassThresholds pass = base;
  read_pass(y, y.root(), pass);
  return pass;
}

namespace {
void list_scalars(const YAML::Node& node, const std::string& path, std::vector<std::string>& out) {
  if (node.IsScalar()) {
    out.push_back(path + " = " + node.Scalar());
  } else if (node.IsMap()) {
    for (const auto& kv : node) list_scalars(kv.second, path + "." + kv.first.Scalar(), out);
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) list_scalars(node[i], path + "[" + std::to_string(i) + "]", out);
  }
}
}  // namespace

std::vector<std::string> realism_overrides(const Scenario& scenario) {
  std::vector<std::string> out;
  if (scenario.text.empty()) return out;
  const YAML::Node root = YAML::Load(scenario.text);
  if (!root.IsMap()) return out;
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    for (const char* section : {"lidar", "body", "weather", "paint", "clocks", "mount_error", "can", "gps", "rtk",
                                "survey", "world_changes", "reference"})
      if (key == section) list_scalars(kv.second, key, out);
  }
  return out;
}

ResolvedScenario resolve_scenario(const Scenario& s, const WorldDescription& d, const World& world) {
  ResolvedScenario r;
  const BuiltPath ego = build_path(s.ego.route, d);
  check_on_network(ego, world.carriageway, s.ego.route.where, "the ego's route");
  r.ego_route = ego.path;
  if (!r.ego_route.closed && s.ego.start_at >= r.ego_route.length)
    throw InputError(s.ego.where + ": start_at is beyond the end of the route (" +
                     std::to_string(int(r.ego_route.length)) + " m)");
  const region::Paths walkable = region::unite(world.carriageway, world.sidewalks);
  for (size_t i = 0; i < s.traffic.size(); ++i) {
    const TrafficSpec& a = s.traffic[i];
    ActorPlan plan;
    plan.name = actor_type_name(a.type) + "_" + std::to_string(i);
    plan.type = a.type;
    if (a.parked) {
      if (!world.bounds.contains(a.position)) throw InputError(a.where + ": parked actor is outside the world");
      plan.path = make_path({a.position, a.position + Eigen::Vector2d(std::cos(a.yaw), std::sin(a.yaw)) * 1e-3}, false);
    } else {
      const BuiltPath built = build_path(a.path, d);
      const bool on_foot = a.type == ActorType::pedestrian || a.type == ActorType::cyclist;
      check_on_network(built, on_foot ? walkable : world.carriageway, a.path.where, "the actor's path");
      plan.path = built.path;
      plan.start_s = a.start_at;
      plan.speed = a.speed;
      plan.depart_ns = int64_t(a.depart_s * 1e9);
      plan.waits = a.waits;
    }
    r.actors.push_back(std::move(plan));
  }
  std::vector<std::string> where;
  for (const TrafficSpec& a : s.traffic) where.push_back(a.path.where);
  std::vector<ActorPlan> parked_by_street;
  for (StreetActor& a : street_actors(s.street, d, s.duration_s, s.seed, s.traffic.size())) {
    const bool on_foot = a.plan.type == ActorType::pedestrian || a.plan.type == ActorType::cyclist;
    if (a.plan.speed > 0)
      check_on_network({a.plan.path, {}}, on_foot ? walkable : world.carriageway, a.where,
                       ("the path of " + a.plan.name).c_str());
    else
      parked_by_street.push_back(a.plan);
    where.push_back(a.where);
    r.actors.push_back(std::move(a.plan));
  }
  // A parked row leaves what room it leaves: the car and every moving vehicle must fit past it, over
  // the stretch each covers in the drive (the ego's at its highest set speed).
  if (!parked_by_street.empty()) {
    const double ego_reach = std::max(s.ego.speed, s.ego.initial_speed) * s.duration_s;
    const double ego_to =
        r.ego_route.closed ? s.ego.start_at + ego_reach : std::min(s.ego.start_at + ego_reach, r.ego_route.length);
    const std::string ego_conflict =
        drives_through_parked(r.ego_route, s.ego.start_at, ego_to, actor_footprint(ActorType::car), parked_by_street);
    if (!ego_conflict.empty())
      throw InputError(s.ego.route.where + ": the ego's route " + ego_conflict +
                       " (`street.parking`); give the route an offset that clears the row");
    for (size_t i = 0; i < r.actors.size(); ++i) {
      const ActorPlan& a = r.actors[i];
      if (a.speed <= 0 || a.type == ActorType::pedestrian || a.type == ActorType::cyclist) continue;
      const std::string conflict = drives_through_parked(
          a.path, actor_distance(a, 0), actor_distance(a, s.duration_ns()), actor_footprint(a.type), parked_by_street);
      if (!conflict.empty()) throw InputError(where[i] + ": " + a.name + " " + conflict + " (`street.parking`)");
    }
  }
  return r;
}

int64_t kidnap_scan_start_ns(const KidnapFault& kidnap, int64_t scan_period_ns) {
  const int64_t due_from = std::llround(kidnap.at_s * double(kNsPerS)) - scan_period_ns / 2;
  return due_from <= 0 ? 0 : (due_from + scan_period_ns - 1) / scan_period_ns * scan_period_ns;
}

}  // namespace lidarloop
