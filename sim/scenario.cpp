#include "sim/scenario.hpp"

#include <cmath>

#include "common/localizer_method.hpp"
#include "common/units.hpp"
#include "common/yaml_reader.hpp"
#include "sim/region.hpp"

namespace lidarloop {
namespace {

constexpr double kMaxDuration = 24 * 3600;  // s
constexpr double kMaxSpeed = 40;            // m/s for any actor
constexpr double kPathCheckStep = 1.0;      // m between on-road checks

std::vector<Wait> read_waits(const YamlReader& y, const YAML::Node& n, const char* what) {
  std::vector<Wait> out;
  if (!n) return out;
  y.expect_sequence(n, what);
  for (const auto& w : n) {
    y.expect_map(w, std::string("an entry of ") + what);
    y.allow_keys(w, {"at", "duration_s"});
    out.push_back({y.number_in(y.required(w, "at"), "at", 0.0, 1e6),
                   y.number_in(y.required(w, "duration_s"), "duration_s", 0.0, kMaxDuration)});
  }
  std::sort(out.begin(), out.end(), [](const Wait& a, const Wait& b) { return a.at < b.at; });
  return out;
}

PathSpec read_path(const YamlReader& y, const YAML::Node& n, const char* what) {
  y.expect_map(n, what);
  y.allow_keys(n,
               {"road", "lane", "direction", "offset", "waypoints", "smoothing_radius", "closed", "crosswalk", "from"});
  PathSpec p;
  p.where = yaml_location(y.file(), n);
  const int kinds = int(bool(n["road"])) + int(bool(n["waypoints"])) + int(bool(n["crosswalk"]));
  if (kinds != 1) y.fail(n, std::string(what) + " needs exactly one of 'road', 'waypoints' or 'crosswalk'");
  if (n["road"]) {
    p.kind = PathSpec::Kind::road;
    p.road = y.string(n["road"], "road");
    if (n["lane"]) {
      const std::string lane = y.string(n["lane"], "lane");
      if (lane != "right" && lane != "left") y.fail(n["lane"], "lane must be right or left, got '" + lane + "'");
      p.lane = lane == "right" ? Lane::right : Lane::left;
    }
    if (n["direction"]) {
      const std::string d = y.string(n["direction"], "direction");
      if (d != "forward" && d != "backward")
        y.fail(n["direction"], "direction must be forward or backward, got '" + d + "'");
      p.backward = d == "backward";
    }
    if (n["offset"]) p.offset = y.number_in(n["offset"], "offset", -30.0, 30.0);
  } else if (n["waypoints"]) {
    p.kind = PathSpec::Kind::waypoints;
    y.expect_sequence(n["waypoints"], "waypoints");
    for (const auto& w : n["waypoints"]) p.waypoints.push_back(y.vec2(w, "a waypoint"));
    if (p.waypoints.size() < 2) y.fail(n["waypoints"], "a path needs at least 2 waypoints");
    for (size_t i = 1; i < p.waypoints.size(); ++i)
      if ((p.waypoints[i] - p.waypoints[i - 1]).norm() < 0.01) y.fail(n["waypoints"][i], "repeated waypoint");
    if (n["smoothing_radius"]) p.smoothing_radius = y.number_in(n["smoothing_radius"], "smoothing_radius", 0.0, 500.0);
    if (n["closed"]) p.closed = y.boolean(n["closed"], "closed");
  } else {
    p.kind = PathSpec::Kind::crosswalk;
    p.crosswalk = int(y.integer_in(n["crosswalk"], "crosswalk", 0, 10000));
    if (n["from"]) {
      const std::string f = y.string(n["from"], "from");
      if (f != "right" && f != "left") y.fail(n["from"], "from must be right or left, got '" + f + "'");
      p.from_left = f == "left";
    }
  }
  for (const char* key : {"lane", "direction", "offset"})
    if (n[key] && p.kind != PathSpec::Kind::road) y.fail(n[key], std::string(key) + " applies only to a road path");
  return p;
}

void read_can(const YamlReader& y, const YAML::Node& n, CanConfig& c) {
  y.expect_map(n, "can");
  y.allow_keys(n, {"rate_hz", "wheel_speed_resolution_mps", "wheel_speed_noise_mps", "wheel_speed_scale_error",
                   "min_detectable_speed_mps", "steering_resolution_rad", "steering_noise_rad", "steering_offset_rad",
                   "latency_ms", "dropout_probability"});
  y.read_number(n, "rate_hz", c.rate_hz, 1.0, 1000.0);
  y.read_number(n, "wheel_speed_resolution_mps", c.wheel_speed_resolution_mps, 0.0, 1.0);
  y.read_number(n, "wheel_speed_noise_mps", c.wheel_speed_noise_mps, 0.0, 5.0);
  y.read_number(n, "wheel_speed_scale_error", c.wheel_speed_scale_error, -0.2, 0.2);
  y.read_number(n, "min_detectable_speed_mps", c.min_detectable_speed_mps, 0.0, 2.0);
  y.read_number(n, "steering_resolution_rad", c.steering_resolution_rad, 0.0, 0.1);
  y.read_number(n, "steering_noise_rad", c.steering_noise_rad, 0.0, 0.5);
  y.read_number(n, "steering_offset_rad", c.steering_offset_rad, -0.5, 0.5);
  y.read_number(n, "dropout_probability", c.dropout_probability, 0.0, 0.99);
  if (n["latency_ms"]) c.latency_ns = std::llround(y.number_in(n["latency_ms"], "latency_ms", 0.0, 1000.0) * 1e6);
}

void read_gps(const YamlReader& y, const YAML::Node& n, GpsConfig& g) {
  y.expect_map(n, "gps");
  y.allow_keys(n, {"rate_hz", "bias_sigma_m", "bias_tau_s", "white_sigma_m", "vertical_sigma_m",
                   "heading_bias_sigma_deg", "heading_bias_tau_s", "heading_white_sigma_deg", "zones"});
  y.read_number(n, "rate_hz", g.rate_hz, 0.1, 100.0);
  y.read_number(n, "bias_sigma_m", g.bias_sigma_m, 0.0, 100.0);
  y.read_number(n, "bias_tau_s", g.bias_tau_s, 0.1, 1e5);
  y.read_number(n, "white_sigma_m", g.white_sigma_m, 0.0, 100.0);
  y.read_number(n, "vertical_sigma_m", g.vertical_sigma_m, 0.0, 100.0);
  if (n["heading_bias_sigma_deg"])
    g.heading_bias_sigma_rad = y.number_in(n["heading_bias_sigma_deg"], "heading_bias_sigma_deg", 0.0, 90.0) * kDeg;
  y.read_number(n, "heading_bias_tau_s", g.heading_bias_tau_s, 0.1, 1e5);
  if (n["heading_white_sigma_deg"])
    g.heading_white_sigma_rad = y.number_in(n["heading_white_sigma_deg"], "heading_white_sigma_deg", 0.0, 90.0) * kDeg;
  if (const YAML::Node zones = n["zones"]) {
    y.expect_sequence(zones, "zones");
    for (const auto& z : zones) {
      y.expect_map(z, "a GPS zone");
      y.allow_keys(z, {"kind", "centre", "radius", "from_s", "to_s", "jump"});
      GpsZone zone;
      const std::string kind = y.string(y.required(z, "kind"), "kind");
      if (kind != "outage" && kind != "multipath")
        y.fail(z["kind"], "zone kind must be outage or multipath, got '" + kind + "'");
      zone.kind = kind == "outage" ? GpsZone::Kind::outage : GpsZone::Kind::multipath;
      if (z["centre"]) zone.centre = y.vec2(z["centre"], "centre");
      if (z["radius"]) zone.radius_m = y.number_in(z["radius"], "radius", 0.1, 1e5);
      if (bool(z["centre"]) != bool(z["radius"])) y.fail(z, "a zone's centre and radius go together");
      if (z["from_s"]) zone.from_ns = int64_t(y.number_in(z["from_s"], "from_s", 0.0, kMaxDuration) * 1e9);
      if (z["to_s"]) zone.to_ns = int64_t(y.number_in(z["to_s"], "to_s", 0.0, kMaxDuration) * 1e9);
      if (zone.to_ns <= zone.from_ns) y.fail(z, "a zone's to_s must be after its from_s");
      if (!z["centre"] && !z["from_s"] && !z["to_s"]) y.fail(z, "a zone needs a centre and radius, or from_s/to_s");
      if (zone.kind == GpsZone::Kind::multipath)
        zone.jump_m = y.vec2(y.required(z, "jump"), "jump");
      else if (z["jump"])
        y.fail(z["jump"], "jump applies only to multipath zones");
      g.zones.push_back(zone);
    }
  }
}

void read_rtk(const YamlReader& y, const YAML::Node& n, RtkConfig& r) {
  y.expect_map(n, "rtk");
  y.allow_keys(n, {"rate_hz", "sigma_m", "heading_sigma_deg"});
  if (n["rate_hz"]) r.rate_hz = y.number_in(n["rate_hz"], "rate_hz", 0.1, 100.0);
  if (n["sigma_m"]) r.sigma_m = y.number_in(n["sigma_m"], "sigma_m", 0.0, 1.0);
  if (n["heading_sigma_deg"])
    r.heading_sigma_rad = y.number_in(n["heading_sigma_deg"], "heading_sigma_deg", 0.0, 10.0) * kDeg;
}

EgoSpec read_ego(const YamlReader& y, const YAML::Node& n, const VehicleParams& vehicle) {
  y.expect_map(n, "ego");
  y.allow_keys(n, {"route", "start_at", "speed", "initial_speed", "stops", "vehicle", "controller"});
  EgoSpec e;
  e.vehicle = vehicle;
  e.where = yaml_location(y.file(), n);
  e.route = read_path(y, y.required(n, "route"), "route");
  if (e.route.kind == PathSpec::Kind::crosswalk) y.fail(n["route"], "the ego cannot drive along a crosswalk");
  if (n["start_at"]) e.start_at = y.number_in(n["start_at"], "start_at", 0.0, 1e6);
  if (n["speed"]) e.speed = y.number_in(n["speed"], "speed", 0.5, kMaxSpeed);
  if (n["initial_speed"]) e.initial_speed = y.number_in(n["initial_speed"], "initial_speed", 0.0, kMaxSpeed);
  e.stops = read_waits(y, n["stops"], "stops");
  if (n["vehicle"]) read_vehicle_params(y, n["vehicle"], e.vehicle);
  if (e.speed > e.vehicle.max_speed) y.fail(n["speed"], "speed is above the vehicle's max_speed");
  if (const YAML::Node c = n["controller"]) {
    y.expect_map(c, "controller");
    y.allow_keys(c, {"stanley_gain", "heading_gain", "preview_s", "max_lateral_accel", "comfort_decel"});
    y.read_number(c, "stanley_gain", e.controller.stanley_gain, 0.0, 20.0);
    y.read_number(c, "heading_gain", e.controller.heading_gain, 0.0, 5.0);
    y.read_number(c, "preview_s", e.controller.preview_s, 0.0, 2.0);
    y.read_number(c, "max_lateral_accel", e.controller.max_lateral_accel, 0.5, 8.0);
    y.read_number(c, "comfort_decel", e.controller.comfort_decel, 0.5, 8.0);
  }
  return e;
}

TrafficSpec read_actor(const YamlReader& y, const YAML::Node& n) {
  y.expect_map(n, "a traffic actor");
  y.allow_keys(n, {"type", "parked", "position", "yaw_deg", "path", "start_at", "speed", "depart_s", "waits"});
  TrafficSpec a;
  a.where = yaml_location(y.file(), n);
  const std::string type = y.string(y.required(n, "type"), "type");
  const auto t = actor_type_from_name(type);
  if (!t) y.fail(n["type"], "unknown actor type '" + type + "' (expected one of: " + actor_type_names() + ")");
  a.type = *t;
  if (n["parked"]) a.parked = y.boolean(n["parked"], "parked");
  if (a.parked) {
    a.position = y.vec2(y.required(n, "position"), "position");
    if (n["yaw_deg"]) a.yaw = y.number_in(n["yaw_deg"], "yaw_deg", -360.0, 360.0) * kDeg;
    for (const char* key : {"path", "speed", "depart_s", "waits", "start_at"})
      if (n[key]) y.fail(n[key], std::string(key) + " makes no sense for a parked actor");
    return a;
  }
  for (const char* key : {"position", "yaw_deg"})
    if (n[key]) y.fail(n[key], std::string(key) + " is for parked actors; a moving one follows its path");
  a.path = read_path(y, y.required(n, "path"), "path");
  a.speed = y.number_in(y.required(n, "speed"), "speed", 0.0, kMaxSpeed);
  if (n["start_at"]) a.start_at = y.number_in(n["start_at"], "start_at", 0.0, 1e6);
  if (n["depart_s"]) a.depart_s = y.number_in(n["depart_s"], "depart_s", 0.0, kMaxDuration);
  a.waits = read_waits(y, n["waits"], "waits");
  return a;
}

Scenario parse(const YamlReader& y, const VehicleParams& vehicle) {
  const YAML::Node& root = y.root();
  y.expect_map(root, "a scenario");
  y.allow_keys(root, {"world", "duration_s", "seed", "ego", "lidar", "can", "gps", "rtk", "traffic", "localizer",
                      "loop", "pass", "output"});
  Scenario s;
  s.file = y.file();
  s.text = y.text();
  s.world = y.string(y.required(root, "world"), "world");
  s.duration_s = y.number_in(y.required(root, "duration_s"), "duration_s", 0.1, kMaxDuration);
  if (root["seed"]) s.seed = uint64_t(y.integer_in(root["seed"], "seed", 0, (1L << 62)));
  s.ego = read_ego(y, y.required(root, "ego"), vehicle);
  if (root["lidar"]) read_hdl32e_config(y, root["lidar"], s.lidar);
  if (root["can"]) read_can(y, root["can"], s.can);
  if (root["gps"]) read_gps(y, root["gps"], s.gps);
  if (root["rtk"]) read_rtk(y, root["rtk"], s.rtk);
  if (const YAML::Node t = root["traffic"]) {
    y.expect_sequence(t, "traffic");
    for (const auto& a : t) s.traffic.push_back(read_actor(y, a));
  }
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
  if (root["loop"]) {
    const std::string loop = y.string(root["loop"], "loop");
    if (loop != "open" && loop != "closed") y.fail(root["loop"], "loop must be open or closed, got '" + loop + "'");
    s.closed_loop = loop == "closed";
  }
  if (const YAML::Node p = root["pass"]) {
    y.expect_map(p, "pass");
    y.allow_keys(p, {"lateral_rmse_m", "longitudinal_rmse_m", "heading_rmse_deg", "max_position_error_m",
                     "max_lane_offset_m", "settle_s"});
    auto opt = [&](const char* key, std::optional<double>& v) {
      if (p[key]) v = y.number_in(p[key], key, 0.0, 1e4);
    };
    opt("lateral_rmse_m", s.pass.lateral_rmse_m);
    opt("longitudinal_rmse_m", s.pass.longitudinal_rmse_m);
    opt("heading_rmse_deg", s.pass.heading_rmse_deg);
    opt("max_position_error_m", s.pass.max_position_error_m);
    opt("max_lane_offset_m", s.pass.max_lane_offset_m);
    if (p["settle_s"]) s.pass.settle_s = y.number_in(p["settle_s"], "settle_s", 0.0, 60.0);
  }
  if (const YAML::Node o = root["output"]) {
    y.expect_map(o, "output");
    y.allow_keys(o, {"scan_every"});
    if (o["scan_every"]) s.scan_every = int(y.integer_in(o["scan_every"], "scan_every", 0, 1000000));
  }
  return s;
}

Path build_path(const PathSpec& p, const WorldDescription& d) {
  switch (p.kind) {
    case PathSpec::Kind::road: {
      const RoadSpec* road = d.road(p.road);
      if (!road) throw InputError(p.where + ": unknown road '" + p.road + "' in world '" + d.name + "'");
      return lane_path(*road, p.lane, p.backward, p.offset ? &*p.offset : nullptr);
    }
    case PathSpec::Kind::waypoints: {
      Polyline2d corners = p.waypoints;
      if (p.closed && (corners.front() - corners.back()).norm() < 0.01) corners.pop_back();
      return make_path(fillet_polyline(corners, p.smoothing_radius, p.closed, 3 * kDeg), p.closed);
    }
    case PathSpec::Kind::crosswalk: {
      if (p.crosswalk >= int(d.crosswalks.size()))
        throw InputError(p.where + ": world '" + d.name + "' has " + std::to_string(d.crosswalks.size()) +
                         " crosswalks; there is no crosswalk " + std::to_string(p.crosswalk));
      const CrosswalkSpec& c = d.crosswalks[size_t(p.crosswalk)];
      return crosswalk_path(*d.road(c.road), c, p.from_left);
    }
  }
  return {};
}

void check_on_network(const Path& path, const region::Paths& area, const std::string& where, const char* what) {
  for (double s = 0; s <= path.length; s += kPathCheckStep) {
    const Pose2d p = path.pose_at(s);
    if (!region::contains(area, {p.x, p.y}))
      throw InputError(where + ": " + what + " leaves the road network at (" + std::to_string(int(std::lround(p.x))) +
                       ", " + std::to_string(int(std::lround(p.y))) + "), " + std::to_string(int(s)) + " m along it");
  }
}

}  // namespace

Scenario load_scenario(const std::string& path, const VehicleParams& vehicle) {
  return parse(YamlReader::open(path), vehicle);
}
Scenario parse_scenario(const std::string& yaml_text, const std::string& name, const VehicleParams& vehicle) {
  return parse(YamlReader::from_string(yaml_text, name), vehicle);
}

ResolvedScenario resolve_scenario(const Scenario& s, const WorldDescription& d, const World& world) {
  ResolvedScenario r;
  r.ego_route = build_path(s.ego.route, d);
  check_on_network(r.ego_route, world.carriageway, s.ego.route.where, "the ego's route");
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
      plan.path = build_path(a.path, d);
      const bool on_foot = a.type == ActorType::pedestrian || a.type == ActorType::cyclist;
      check_on_network(plan.path, on_foot ? walkable : world.carriageway, a.path.where, "the actor's path");
      plan.start_s = a.start_at;
      plan.speed = a.speed;
      plan.depart_ns = int64_t(a.depart_s * 1e9);
      plan.waits = a.waits;
    }
    r.actors.push_back(std::move(plan));
  }
  return r;
}

}  // namespace lidarloop
