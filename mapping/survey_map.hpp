#pragma once
// The survey behind the HD map: the lanes the mapping drive follows, in the order driven, with the
// survey car's pose error along them (mapping/survey_error.hpp), and the curb layer as a map annotator
// draws it from the surveyed point cloud: every curb where the survey put it, not where it is.
#include <vector>

#include <Eigen/Geometry>

#include "common/curb_map_file.hpp"
#include "mapping/survey_error.hpp"
#include "sim/path.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct SurveyLane {
  // In the WorldDescription the survey was planned from (which must outlive it); null on a world from
  // a Lanelet2 map, whose lanes are chains of lanelets.
  const RoadSpec* road;
  bool backward;
  Path path;
  double start_m;           // distance driven before this lane: the survey error runs on across lanes
  Eigen::AlignedBox2d box;  // of the lane's centre line
};

struct SurveyDrive {
  std::vector<SurveyLane> lanes;
  double length_m = 0;     // every lane, end to end
  SurveyErrorTrack error;  // over the distance driven, 0 to length_m
};

// Every lane of every road, right and left lanes of each travel direction that has them (both
// directions on two-way roads), or on a Lanelet2 map every drivable lanelet (sim/lane_graph.hpp's
// covering_routes), with the survey error drawn from `rng` over their total length.
SurveyDrive plan_survey(const WorldDescription& description, const SurveyErrorConfig& config, std::mt19937_64& rng);

// The point of the survey nearest to p, over every lane: the car's true pose there and the distance
// driven when it was there.
struct SurveyPoint {
  Pose2d truth;
  double s = 0;
};
SurveyPoint nearest_survey_point(const SurveyDrive& drive, const Eigen::Vector2d& p);

// The same curbs with vertices at most `spacing_m` apart (the original vertices kept, in order), so
// a long straight curb carries the survey error's variation along it. Every other field is kept.
CurbMap densify_curb_map(const CurbMap& map, double spacing_m);

// The curb layer of the surveyed map: each point of the world's curbs moved by the survey error of the
// nearest survey pose (position error plus heading error turned about that pose), which is where the
// curb appears in the point cloud a map annotator draws it from. Only the points move; every other
// field of the map and of each curb is kept. Densify first (densify_curb_map) for errors that vary along
// long straight curbs. A zero error gives back the same points bit for bit.
//
// Drawn from the world's exact curb lines rather than detected in the surveyed scans: the curb
// detector is what the scenarios test, and a map made by it would be scored against itself (its
// misses and false curbs would be in the map too, and would agree with the scans).
CurbMap survey_curb_map(const CurbMap& world_curbs, const SurveyDrive& drive);

// How far a surveyed curb map's points lie from the world's, point by point (the two maps have the
// same curbs and vertices: `surveyed` = survey_curb_map(world_curbs, ...)). `across` is the shift's
// component across the world's curb line at the vertex (positive to the left of the line's direction),
// what a localizer matching curbs sees; `shift` the whole planar displacement.
struct CurbShiftStats {
  size_t points = 0;
  double across_mean_m = 0, across_sigma_m = 0, across_max_abs_m = 0;
  double shift_mean_m = 0, shift_max_m = 0;
};
CurbShiftStats curb_shift_stats(const CurbMap& world_curbs, const CurbMap& surveyed);

}  // namespace lidarloop
