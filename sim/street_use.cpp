#include "sim/street_use.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "common/input_error.hpp"
#include "sim/counter_rng.hpp"
#include "sim/curb_band.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr uint64_t kStreetStream = 0x737472656574;  // "street"
// A walker or rider slower than this is standing still: the speed draws are cut off here.
constexpr double kMinSpeedMps = 0.3;
// Spacing of the points along a road at which its carriageway is tested against another road's curb:
// far below any road's width, so no junction's mouth is missed.
constexpr double kJunctionProbeStepM = 1.0;
// Spacing of a bus line's points: fine enough that its pull-in is a smooth curve.
constexpr double kBusLineStepM = 1.0;
// Spacing of the poses at which a moving vehicle is tested against the parked ones, and how much of
// each footprint's edge may touch without counting (the meshes' rounding and mirrors).
constexpr double kDriveThroughStepM = 0.5, kDriveThroughToleranceM = 0.05;

// Draws in a fixed order from one counter-based stream, so the actors depend on the seed alone.
struct Draws {
  CounterRng rng;
  uint64_t next = 0;
  double uniform() { return rng.uniform(next++); }
  double normal() { return rng.normal(next++); }
  double speed(double mean, double sigma) { return std::max(kMinSpeedMps, mean + sigma * normal()); }
};

struct RoadRef {
  const RoadSpec* road;
  int index;
  double length;
};

RoadRef road_of(const WorldDescription& d, const std::string& name, const std::string& where) {
  if (d.roads.empty())
    throw InputError(where + ": `street` needs a world described by roads; world '" + d.name +
                     "' comes from a map without them (place its actors under `traffic`)");
  const RoadSpec* road = d.road(name);
  if (!road) throw InputError(where + ": unknown road '" + name + "' in world '" + d.name + "'");
  return {road, int(road - d.roads.data()), polyline_length(road->centreline)};
}

// [from, to] of a stretch on its road, checked.
std::pair<double, double> span_of(const StreetStretch& st, const RoadRef& r) {
  const double to = st.to < 0 ? r.length : st.to;
  if (!(st.from >= 0 && st.from < to && to <= r.length + 1e-6))
    throw InputError(st.where + ": the stretch must lie along road '" + st.road + "' (0 to " +
                     std::to_string(int(r.length)) + " m) with from < to");
  return {st.from, to};
}

std::vector<RoadSide> sides_of(RoadSide side) {
  if (side == RoadSide::both) return {RoadSide::right, RoadSide::left};
  return {side};
}

// +1 for the left of the centreline's direction, -1 for the right: lateral offsets are positive left.
double sign_of(RoadSide side) { return side == RoadSide::left ? 1.0 : -1.0; }

// Traffic on this side travels against the centreline's direction (the left of a two-way road).
bool against_centreline(const RoadSpec& road, RoadSide side) { return side == RoadSide::left && !road.one_way; }

Eigen::Vector2d beside_centreline(const RoadSpec& road, double s, double lateral) {
  const PolylineSample at = sample_polyline(road.centreline, s);
  return at.point + Eigen::Vector2d(-at.tangent.y(), at.tangent.x()) * lateral;
}

// A path parallel to the centreline at `lateral`, driven with or against it, and the arc length on it
// beside centreline arc length `s`.
std::pair<Path, double> parallel_path(const RoadSpec& road, double lateral, bool backward, double s) {
  Path path = lane_path(road, Lane::right, backward, &lateral);
  const double on_path = path.project(beside_centreline(road, s, lateral));
  return {std::move(path), on_path};
}

std::string actor_name(ActorType type, size_t index) { return actor_type_name(type) + "_" + std::to_string(index); }

struct Builder {
  const WorldDescription& world;
  const std::vector<BusStopSpec>& bus_stops;
  Draws draws;
  size_t next_index;
  std::vector<StreetActor> out;

  void add(ActorPlan plan, const std::string& where) {
    plan.name = actor_name(plan.type, next_index++);
    out.push_back({std::move(plan), where});
  }

  // The stretches of one side of a road where no one may park: curb cuts, crosswalks and the mouths of
  // the roads that meet it on that side, each with the clearance.
  std::vector<std::pair<double, double>> no_parking(const RoadRef& r, RoadSide side, const ParkingConfig& c) const {
    std::vector<std::pair<double, double>> out;
    for (const CurbCutSpan& cut : curb_cuts_of(world, r.index, side)) out.push_back({cut.from, cut.to});
    for (const CrosswalkSpec& x : world.crosswalks)
      if (x.road == r.road->name)
        out.push_back({x.at - x.width / 2 - c.crosswalk_clearance_m, x.at + x.width / 2 + c.crosswalk_clearance_m});
    for (const BusStopSpec& b : bus_stops)
      if (b.road == r.road->name && b.side == side) {
        const double zone = actor_footprint(ActorType::bus).length / 2 + b.pull_in_m;
        out.push_back({b.at - zone, b.at + zone});
      }
    const Path centre = make_path(r.road->centreline, r.road->closed);
    for (const RoadSpec& other : world.roads) {
      if (&other == r.road) continue;
      // Wherever the other carriageway reaches this side's curb, this curb is a junction's mouth.
      const double reach = r.road->width / 2 + other.width / 2;
      const double other_length = polyline_length(other.centreline);
      for (double t = 0; t <= other_length; t += kJunctionProbeStepM) {
        const Eigen::Vector2d p = sample_polyline(other.centreline, t).point;
        const double s = centre.project(p);
        const Pose2d on = centre.pose_at(s);
        const double lateral = -std::sin(on.yaw) * (p.x() - on.x) + std::cos(on.yaw) * (p.y() - on.y);
        if (std::abs(lateral) < reach && lateral * sign_of(side) > 0)
          out.push_back({s - other.width / 2 - c.crosswalk_clearance_m, s + other.width / 2 + c.crosswalk_clearance_m});
      }
    }
    // On a closed road a span's clearance reaching past either end of the centreline continues from
    // the other end.
    if (r.road->closed)
      for (size_t i = 0, n = out.size(); i < n; ++i) {
        if (out[i].first < 0) out.push_back({out[i].first + r.length, out[i].second + r.length});
        if (out[i].second > r.length) out.push_back({out[i].first - r.length, out[i].second - r.length});
      }
    return out;
  }

  void parking(const ParkingConfig& c) {
    for (const StreetStretch& st : c.stretches) {
      const RoadRef r = road_of(world, st.road, st.where);
      const auto [from, to] = span_of(st, r);
      for (RoadSide side : sides_of(st.side)) {
        const auto blocked = no_parking(r, side, c);
        const auto free = [&](double a, double b) {
          return std::none_of(blocked.begin(), blocked.end(),
                              [&](const auto& x) { return a < x.second && b > x.first; });
        };
        for (double s = from; s + c.stall_length_m <= to + 1e-9;) {
          if (!free(s, s + c.stall_length_m) || draws.uniform() >= c.occupancy) {
            s += c.stall_length_m;
            continue;
          }
          // A van or truck takes as many stalls as its length needs, if they are free; else a car parks.
          ActorType type = draws.uniform() < c.truck_share ? ActorType::truck : ActorType::car;
          int stalls = int(std::ceil(actor_footprint(type).length / c.stall_length_m));
          const double end = s + stalls * c.stall_length_m;
          if (stalls > 1 && (end > to + 1e-9 || !free(s, end))) type = ActorType::car, stalls = 1;
          const double half_width = actor_footprint(type).width / 2;
          const double lateral = sign_of(side) * (r.road->width / 2 - c.curb_gap_m - half_width);
          const double centre = s + stalls * c.stall_length_m / 2;
          const PolylineSample at = sample_polyline(r.road->centreline, centre);
          double yaw = std::atan2(at.tangent.y(), at.tangent.x());
          if (against_centreline(*r.road, side)) yaw += std::numbers::pi;
          const Eigen::Vector2d p = beside_centreline(*r.road, centre, lateral);
          ActorPlan plan;
          plan.type = type;
          plan.path = make_path({p, p + Eigen::Vector2d(std::cos(yaw), std::sin(yaw)) * 1e-3}, false);
          add(std::move(plan), st.where);
          s += stalls * c.stall_length_m;
        }
      }
    }
  }

  // Walkers or riders spread uniformly along each side of each stretch, `count_per_m` of them a metre.
  void along(const std::vector<StreetStretch>& stretches, double count_per_m, ActorType type, double speed_mps,
             double speed_sigma_mps, double lateral_from_curb, bool with_traffic) {
    for (const StreetStretch& st : stretches) {
      const RoadRef r = road_of(world, st.road, st.where);
      const auto [from, to] = span_of(st, r);
      for (RoadSide side : sides_of(st.side)) {
        const int n = int(std::lround(count_per_m * (to - from)));
        const double lateral = sign_of(side) * (r.road->width / 2 + lateral_from_curb);
        for (int i = 0; i < n; ++i) {
          const double s = from + draws.uniform() * (to - from);
          const bool backward = with_traffic ? against_centreline(*r.road, side) : draws.uniform() < 0.5;
          auto [path, start] = parallel_path(*r.road, lateral, backward, s);
          ActorPlan plan;
          plan.type = type;
          plan.path = std::move(path);
          plan.start_s = start;
          plan.speed = draws.speed(speed_mps, speed_sigma_mps);
          add(std::move(plan), st.where);
        }
      }
    }
  }

  void crossings(const CrossingPedestrianConfig& c, const SidewalkPedestrianConfig& walk, double duration_s,
                 const std::string& where) {
    if (c.per_minute <= 0) return;
    std::vector<int> chosen = c.crosswalks;
    if (chosen.empty())
      for (size_t i = 0; i < world.crosswalks.size(); ++i) chosen.push_back(int(i));
    for (int index : chosen) {
      if (index < 0 || size_t(index) >= world.crosswalks.size())
        throw InputError(where + ": world '" + world.name + "' has " + std::to_string(world.crosswalks.size()) +
                         " crosswalks; there is no crosswalk " + std::to_string(index));
      const CrosswalkSpec& x = world.crosswalks[size_t(index)];
      const RoadRef r = road_of(world, x.road, where);
      // Poisson arrivals: exponential gaps at the rate.
      const double rate_per_s = c.per_minute / 60;
      for (double t = -std::log(1 - draws.uniform()) / rate_per_s; t < duration_s;
           t += -std::log(1 - draws.uniform()) / rate_per_s) {
        const bool from_left = draws.uniform() < 0.5;
        const double before = x.at + (2 * draws.uniform() - 1) * c.spread_m;
        const double after = x.at + (2 * draws.uniform() - 1) * c.spread_m;
        const double near = (from_left ? 1.0 : -1.0) * (r.road->width / 2 + walk.from_curb_m);
        const Path across = crosswalk_path(*r.road, x, from_left);
        const auto on_road = [&](double s) { return std::clamp(s, 0.0, r.length); };
        Polyline2d line = {beside_centreline(*r.road, on_road(before), near)};
        line.insert(line.end(), across.points.begin(), across.points.end());
        line.push_back(beside_centreline(*r.road, on_road(after), -near));
        ActorPlan plan;
        plan.type = ActorType::pedestrian;
        plan.path = make_path(std::move(line), false);
        plan.speed = draws.speed(c.speed_mps, c.speed_sigma_mps);
        plan.depart_ns = int64_t(t * 1e9);
        add(std::move(plan), where);
      }
    }
  }

  // The bus's line: the centre of its side's curb lane, moving to the curb over pull_in_m before the
  // stop and back after it, sampled along the whole road, in its direction of travel.
  Path bus_line(const BusStopSpec& b, const RoadRef& r) const {
    const RoadSpec& road = *r.road;
    const double lane = std::abs(lane_offset(road, Lane::right, false));  // the curb lane's, on either side
    const double curb = road.width / 2 - b.curb_gap_m - actor_footprint(ActorType::bus).width / 2;
    const double hold = actor_footprint(ActorType::bus).length / 2;
    Polyline2d line;
    for (double s = 0; s < r.length; s += kBusLineStepM) {
      double d = std::abs(s - b.at);
      if (road.closed) d = std::min(d, r.length - d);
      const double w = std::clamp(1 - (d - hold) / b.pull_in_m, 0.0, 1.0);
      line.push_back(beside_centreline(road, s, sign_of(b.side) * (lane + (curb - lane) * w)));
    }
    if (road.closed) {
      line.push_back(line.front());
    } else {
      line.push_back(beside_centreline(road, r.length, sign_of(b.side) * lane));
    }
    if (against_centreline(road, b.side)) std::reverse(line.begin(), line.end());
    return make_path(std::move(line), road.closed);
  }

  void bus_stop(const BusStopSpec& b) {
    const RoadRef r = road_of(world, b.road, b.where);
    if (!(b.at >= 0 && b.at <= r.length))
      throw InputError(b.where + ": the stop must lie along road '" + b.road + "' (0 to " +
                       std::to_string(int(r.length)) + " m)");
    const double curb = r.road->width / 2 - b.curb_gap_m - actor_footprint(ActorType::bus).width / 2;
    Path path = bus_line(b, r);
    double stop = path.project(beside_centreline(*r.road, b.at, sign_of(b.side) * curb));
    ActorPlan plan;
    plan.type = ActorType::bus;
    plan.speed = b.speed_mps;
    const double approach = b.speed_mps * b.arrive_s;
    if (path.closed) {
      plan.start_s = path.wrap(stop - approach);
      if (stop < plan.start_s) stop += path.length;  // the wait is ahead, on the next lap's arc length
    } else if (approach <= stop) {
      plan.start_s = stop - approach;
    } else {  // it cannot have come from before the road's start: it sets off later
      plan.depart_ns = int64_t((b.arrive_s - stop / b.speed_mps) * 1e9);
    }
    plan.path = std::move(path);
    plan.waits = {{stop, b.dwell_s}};
    add(std::move(plan), b.where);
  }
};

std::vector<StreetStretch> read_stretches(const YamlReader& y, YamlMap& section) {
  std::vector<StreetStretch> out;
  const YAML::Node list = section.required("stretches");
  y.expect_sequence(list, "stretches");
  for (const auto& n : list) {
    YamlMap m(y, n, "a stretch");
    StreetStretch st;
    st.where = m.where();
    st.road = y.string(m.required("road"), "road");
    if (const YAML::Node side = m["side"]) st.side = read_side(y, side);
    m.number("from", st.from, 0.0, 1e6).number("to", st.to, 0.0, 1e6);
    m.done();
    out.push_back(std::move(st));
  }
  return out;
}

// Whether two footprints (centre, heading, size) overlap, by the separating axis theorem.
bool footprints_overlap(const Pose2d& a, const ActorFootprint& fa, const Pose2d& b, const ActorFootprint& fb) {
  const Eigen::Vector2d ca(a.x, a.y), cb(b.x, b.y);
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)},
                                   {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)},
                                   {-std::sin(b.yaw), std::cos(b.yaw)}};
  const auto reach = [&](const ActorFootprint& f, const Eigen::Vector2d& u, const Eigen::Vector2d& v,
                         const Eigen::Vector2d& axis) {
    return (f.length / 2 - kDriveThroughToleranceM) * std::abs(u.dot(axis)) +
           (f.width / 2 - kDriveThroughToleranceM) * std::abs(v.dot(axis));
  };
  for (const Eigen::Vector2d& axis : axes)
    if (std::abs((cb - ca).dot(axis)) > reach(fa, axes[0], axes[1], axis) + reach(fb, axes[2], axes[3], axis))
      return false;
  return true;
}

}  // namespace

std::string drives_through_parked(const Path& path, double from_s, double to_s, const ActorFootprint& footprint,
                                  const std::vector<ActorPlan>& parked) {
  for (double s = from_s; s <= to_s; s += kDriveThroughStepM) {
    const Pose2d p = path.pose_at(s);
    for (const ActorPlan& a : parked) {
      const Pose2d q = a.path.pose_at(0);
      const ActorFootprint f = actor_footprint(a.type);
      if (std::hypot(p.x - q.x, p.y - q.y) > (footprint.length + f.length) / 2) continue;
      if (footprints_overlap(p, footprint, q, f)) {
        std::ostringstream msg;
        msg << std::fixed << std::setprecision(1) << "drives through the parked " << a.name << " at (" << q.x << ", "
            << q.y << "), " << s << " m along its path";
        return msg.str();
      }
    }
  }
  return "";
}

void read_street_use(const YamlReader& y, const YAML::Node& node, StreetUse& street) {
  YamlMap root(y, node, "street");
  if (const YAML::Node n = root["parking"]) {
    YamlMap m(y, n, "street.parking");
    ParkingConfig& c = street.parking;
    c.stretches = read_stretches(y, m);
    m.number("occupancy", c.occupancy, 0.0, 1.0)
        .number("stall_length_m", c.stall_length_m, 4.0, 20.0)
        .number("curb_gap_m", c.curb_gap_m, 0.0, 1.0)
        .number("crosswalk_clearance_m", c.crosswalk_clearance_m, 0.0, 50.0)
        .number("truck_share", c.truck_share, 0.0, 1.0)
        .done();
  }
  if (const YAML::Node n = root["sidewalk_pedestrians"]) {
    YamlMap m(y, n, "street.sidewalk_pedestrians");
    SidewalkPedestrianConfig& c = street.sidewalk_pedestrians;
    c.stretches = read_stretches(y, m);
    m.number("per_100m", c.per_100m, 0.0, 200.0)
        .number("speed_mps", c.speed_mps, 0.3, 3.0)
        .number("speed_sigma_mps", c.speed_sigma_mps, 0.0, 1.0)
        .number("from_curb_m", c.from_curb_m, 0.0, 10.0)
        .done();
  }
  if (const YAML::Node n = root["crossing_pedestrians"]) {
    YamlMap m(y, n, "street.crossing_pedestrians");
    CrossingPedestrianConfig& c = street.crossing_pedestrians;
    c.where = m.where();
    m.number("per_minute", c.per_minute, 0.0, 120.0)
        .number("speed_mps", c.speed_mps, 0.3, 3.0)
        .number("speed_sigma_mps", c.speed_sigma_mps, 0.0, 1.0)
        .number("spread_m", c.spread_m, 0.0, 100.0);
    if (const YAML::Node list = m["crosswalks"]) {
      y.expect_sequence(list, "crosswalks");
      for (const auto& i : list) c.crosswalks.push_back(int(y.integer_in(i, "crosswalk", 0, 100000)));
    }
    m.done();
  }
  if (const YAML::Node n = root["cyclists"]) {
    YamlMap m(y, n, "street.cyclists");
    CyclistConfig& c = street.cyclists;
    c.stretches = read_stretches(y, m);
    m.number("per_km", c.per_km, 0.0, 1000.0)
        .number("speed_mps", c.speed_mps, 1.0, 15.0)
        .number("speed_sigma_mps", c.speed_sigma_mps, 0.0, 5.0)
        .number("from_curb_m", c.from_curb_m, 0.3, 3.0)
        .done();
  }
  if (const YAML::Node list = root["bus_stops"]) {
    y.expect_sequence(list, "bus_stops");
    for (const auto& n : list) {
      YamlMap m(y, n, "a bus stop");
      BusStopSpec b;
      b.where = m.where();
      b.road = y.string(m.required("road"), "road");
      if (const YAML::Node side = m["side"]) {
        b.side = read_side(y, side);
        if (b.side == RoadSide::both) y.fail(side, "a bus stop is on one side: left or right");
      }
      b.at = y.number_in(m.required("at"), "at", 0.0, 1e6);
      b.arrive_s = y.number_in(m.required("arrive_s"), "arrive_s", 0.0, 1e5);
      m.number("dwell_s", b.dwell_s, 0.0, 3600.0)
          .number("pull_in_m", b.pull_in_m, 1.0, 100.0)
          .number("speed_mps", b.speed_mps, 1.0, 30.0)
          .number("curb_gap_m", b.curb_gap_m, 0.0, 1.0)
          .done();
      street.bus_stops.push_back(std::move(b));
    }
  }
  root.done();
}

bool StreetUse::empty() const {
  return parking.stretches.empty() && sidewalk_pedestrians.stretches.empty() && crossing_pedestrians.per_minute <= 0 &&
         cyclists.stretches.empty() && bus_stops.empty();
}

std::vector<StreetActor> street_actors(const StreetUse& street, const WorldDescription& world, double duration_s,
                                       uint64_t seed, size_t first_index) {
  Builder b{world, street.bus_stops, {CounterRng(seed, kStreetStream)}, first_index, {}};
  b.parking(street.parking);
  const SidewalkPedestrianConfig& walk = street.sidewalk_pedestrians;
  b.along(walk.stretches, walk.per_100m / 100, ActorType::pedestrian, walk.speed_mps, walk.speed_sigma_mps,
          walk.from_curb_m, false);
  b.crossings(street.crossing_pedestrians, walk, duration_s, street.crossing_pedestrians.where);
  const CyclistConfig& bike = street.cyclists;
  b.along(bike.stretches, bike.per_km / 1000, ActorType::cyclist, bike.speed_mps, bike.speed_sigma_mps,
          -bike.from_curb_m, true);
  for (const BusStopSpec& stop : street.bus_stops) b.bus_stop(stop);
  return std::move(b.out);
}

}  // namespace lidarloop
