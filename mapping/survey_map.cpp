#include "mapping/survey_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sim/lane_graph.hpp"
#include "sim/lanelet2_world.hpp"
#include "sim/opendrive_world.hpp"

namespace lidarloop {

namespace {

// A curb of a CurbMap is its polyline, or a record holding it as `points` beside its own properties
// (curb kind, ...): either way only the points are read or moved here.
template <class Curb>
Polyline2d& points_of(Curb& curb) {
  if constexpr (requires { curb.points; })
    return curb.points;
  else
    return curb;
}
template <class Curb>
const Polyline2d& points_of(const Curb& curb) {
  if constexpr (requires { curb.points; })
    return curb.points;
  else
    return curb;
}

// A SLAM map's error sampled along the drive, every config.sample_spacing_m of distance driven, at the
// place the survey car is then (the error belongs to the place, mapping/slam_map_error.hpp). Between
// the last sample of one lane and the first of the next the track interpolates between two places, over
// less than one spacing of distance.
SurveyErrorTrack slam_error_along(const SurveyDrive& drive, const SurveyErrorConfig& c, std::mt19937_64& rng) {
  if (!(c.sample_spacing_m > 0)) throw std::invalid_argument("survey error: the sample spacing must be positive");
  const SlamErrorField field(c.slam, rng);
  SurveyErrorTrack track;
  track.spacing_m = c.sample_spacing_m;
  const size_t n = size_t(std::ceil(drive.length_m / c.sample_spacing_m)) + 1;
  track.samples.reserve(n);
  size_t lane = 0;
  for (size_t k = 0; k < n; ++k) {
    const double s = std::min(double(k) * c.sample_spacing_m, drive.length_m);
    while (lane + 1 < drive.lanes.size() && s > drive.lanes[lane].start_m + drive.lanes[lane].path.length) ++lane;
    if (drive.lanes.empty()) {
      track.samples.push_back({});
      continue;
    }
    const Pose2d at = drive.lanes[lane].path.pose_at(s - drive.lanes[lane].start_m);
    track.samples.push_back(field.at({at.x, at.y}));
  }
  return track;
}

}  // namespace

SurveyDrive plan_survey(const WorldDescription& d, const SurveyErrorConfig& config, std::mt19937_64& rng) {
  SurveyDrive drive;
  auto add = [&](const RoadSpec& road, Lane lane, bool backward) {
    SurveyLane l{&road, backward, lane_path(road, lane, backward), drive.length_m, {}};
    for (const auto& p : l.path.points) l.box.extend(p);
    drive.length_m += l.path.length;
    drive.lanes.push_back(std::move(l));
  };
  if (d.lanelet2) {  // a Lanelet2 map: chains of lanelets that together drive every one of them
    const LaneGraph& graph = d.lanelet2->graph;
    for (const auto& route : covering_routes(graph)) {
      SurveyLane l{nullptr, false, make_path(route_driven_line(graph, route), false), drive.length_m, {}};
      for (const auto& p : l.path.points) l.box.extend(p);
      drive.length_m += l.path.length;
      drive.lanes.push_back(std::move(l));
    }
  }
  if (d.opendrive) {  // an OpenDRIVE map: the same, on its driving lanes through the junctions
    const LaneGraph& graph = d.opendrive->graph.graph;
    for (const auto& route : covering_routes(graph)) {
      SurveyLane l{nullptr, false, make_path(route_centreline(graph, route), false), drive.length_m, {}};
      for (const auto& p : l.path.points) l.box.extend(p);
      drive.length_m += l.path.length;
      drive.lanes.push_back(std::move(l));
    }
  }
  for (const auto& road : d.roads) {
    const int per_direction = road.one_way ? road.lanes : std::max(1, road.lanes / 2);
    for (bool backward : {false, true}) {
      if (backward && road.one_way) continue;
      add(road, Lane::right, backward);
      if (per_direction >= 2) add(road, Lane::left, backward);
    }
  }
  drive.error = config.provenance == MapProvenance::slam ? slam_error_along(drive, config, rng)
                                                         : simulate_survey_error(config, drive.length_m, rng);
  return drive;
}

SurveyPoint nearest_survey_point(const SurveyDrive& drive, const Eigen::Vector2d& p) {
  SurveyPoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (const SurveyLane& lane : drive.lanes) {
    const double to_box = lane.box.exteriorDistance(p);
    if (to_box * to_box >= best_d2) continue;
    const double s = lane.path.project(p);
    const Pose2d at = lane.path.pose_at(s);
    const double d2 = (Eigen::Vector2d(at.x, at.y) - p).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = {at, lane.start_m + s};
  }
  return best;
}

CurbMap densify_curb_map(const CurbMap& map, double spacing_m) {
  if (!(spacing_m > 0)) throw std::invalid_argument("densify_curb_map: spacing must be positive");
  CurbMap out = map;
  for (auto& curb : out.curbs) {
    Polyline2d& line = points_of(curb);
    if (line.size() < 2) continue;
    Polyline2d dense{line.front()};
    for (size_t i = 1; i < line.size(); ++i) {
      const Eigen::Vector2d a = line[i - 1], b = line[i];
      const int steps = std::max(1, int(std::ceil((b - a).norm() / spacing_m)));
      for (int k = 1; k < steps; ++k) dense.push_back(a + (b - a) * (double(k) / steps));
      dense.push_back(b);
    }
    line = std::move(dense);
  }
  return out;
}

CurbMap survey_curb_map(const CurbMap& world_curbs, const SurveyDrive& drive) {
  CurbMap out = world_curbs;
  for (auto& curb : out.curbs)
    for (Eigen::Vector2d& p : points_of(curb)) {
      const SurveyPoint at = nearest_survey_point(drive, p);
      p = surveyed_point(p, {at.truth.x, at.truth.y}, drive.error.at(at.s));
    }
  return out;
}

CurbShiftStats curb_shift_stats(const CurbMap& world_curbs, const CurbMap& surveyed) {
  if (world_curbs.curbs.size() != surveyed.curbs.size())
    throw std::invalid_argument("curb_shift_stats: the maps have different curbs");
  CurbShiftStats st;
  double sum = 0, sum2 = 0, shift_sum = 0;
  for (size_t c = 0; c < world_curbs.curbs.size(); ++c) {
    const Polyline2d& a = points_of(world_curbs.curbs[c]);
    const Polyline2d& b = points_of(surveyed.curbs[c]);
    if (a.size() != b.size()) throw std::invalid_argument("curb_shift_stats: a curb has different vertices");
    if (a.size() < 2) continue;
    // A closed ring repeats its first point: count it once.
    const size_t n = (a.front() - a.back()).norm() == 0 ? a.size() - 1 : a.size();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d along = a[std::min(i + 1, a.size() - 1)] - a[i == 0 ? 0 : i - 1];
      if (along.norm() == 0) continue;
      const Eigen::Vector2d left = Eigen::Vector2d(-along.y(), along.x()).normalized();
      const Eigen::Vector2d shift = b[i] - a[i];
      const double across = shift.dot(left);
      sum += across, sum2 += across * across, shift_sum += shift.norm();
      st.across_max_abs_m = std::max(st.across_max_abs_m, std::abs(across));
      st.shift_max_m = std::max(st.shift_max_m, shift.norm());
      ++st.points;
    }
  }
  if (st.points == 0) return st;
  const double n = double(st.points);
  st.across_mean_m = sum / n;
  st.across_sigma_m = std::sqrt(std::max(0.0, sum2 / n - st.across_mean_m * st.across_mean_m));
  st.shift_mean_m = shift_sum / n;
  return st;
}

}  // namespace lidarloop
