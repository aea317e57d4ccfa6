#pragma once
// The height of the ground a world is built on, before curbs: the terrain (hills give roads their
// grade), the carriageway's crown (it falls from each road's centreline towards its curbs) or, through
// curves, its superelevation, and the pavement's roughness. The world builder meshes these heights; vehicles rest on
// them.
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "common/pose2d.hpp"

#include "sim/world_description.hpp"

namespace lidarloop {

struct PointsKdTree;

// Where a point lies relative to the nearest road centreline.
struct RoadPoint {
  int road = -1;        // index into WorldDescription::roads
  double s = 0;         // arc length along the centreline, m
  double lateral = 0;   // signed offset, left of the centreline's direction positive, m
  double distance = 0;  // from the centreline, m (= |lateral| beside the road, more past its ends)
  Eigen::Vector2d tangent{1, 0};
};

class RoadSurface {
 public:
  explicit RoadSurface(const WorldDescription& description);
  // A surface given by functions instead of road centrelines (a Lanelet2 map's, sim/lanelet2_world.hpp):
  // terrain and crown as the functions say, roughness as `geometry`'s ISO 8608 class; it has no roads,
  // so nearest_road() finds none.
  using HeightFunction = std::function<double(const Eigen::Vector2d&)>;
  RoadSurface(HeightFunction terrain, HeightFunction crown, const WorldGeometryParams& geometry);
  ~RoadSurface();
  RoadSurface(const RoadSurface&) = delete;
  RoadSurface& operator=(const RoadSurface&) = delete;

  double terrain(const Eigen::Vector2d& p) const;    // hills
  double crown(const Eigen::Vector2d& p) const;      // the crown's fall, or the curve's bank, from the centreline
  double roughness(const Eigen::Vector2d& p) const;  // zero-mean pavement unevenness
  double carriageway(const Eigen::Vector2d& p) const { return terrain(p) + crown(p) + roughness(p); }
  RoadPoint nearest_road(const Eigen::Vector2d& p) const;

 private:
  struct Sample {
    int road;
    double s;
    Eigen::Vector2d tangent;
    bool at_start, at_end;  // the first or last sample of an open road
    double bank;            // superelevation, signed: positive banks towards the left
  };
  struct Wave {
    Eigen::Vector2d wavenumber;  // rad/m
    double amplitude, phase;
  };
  std::vector<double> cross_slope_;  // per road
  std::vector<Hill> hills_;
  std::vector<Eigen::Vector2d> points_;  // centreline samples, for the KD-tree
  std::vector<Sample> samples_;
  std::unique_ptr<PointsKdTree> index_;
  std::vector<Wave> waves_;
  HeightFunction terrain_fn_, crown_fn_;  // set by the second constructor only
  void add_roughness(const WorldGeometryParams& geometry);
};

// Height of whatever a wheel or a foot stands on at a point.
using GroundHeight = std::function<double(const Eigen::Vector2d&)>;

// A rigid vehicle body resting on the ground with its four wheels (no suspension: the body's own
// motion is another model): `pose` is the rear axle's centre; z, pitch and roll are the plane through
// the mid-points of the axles and of the sides.
Eigen::Isometry3d rest_on_ground(const Pose2d& pose, const GroundHeight& ground, double wheelbase, double track);

// The same in two halves, for callers that interpolate the contact between poses: where the four
// wheels put the rear axle's centre (height) and the plane (pitch, roll), then the body's pose on it.
struct GroundContact {
  double z = 0, pitch = 0, roll = 0;
};
GroundContact ground_contact(const Pose2d& pose, const GroundHeight& ground, double wheelbase, double track);
Eigen::Isometry3d on_ground(const Pose2d& pose, const GroundContact& contact);

// ISO 8608 displacement PSD at the reference spatial frequency 0.1 cycles/m, m^3, for classes A-E.
double iso8608_psd(char road_class);

}  // namespace lidarloop
