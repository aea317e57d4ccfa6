#pragma once
// The band along every curb line, from the gutter's lip to the back of the curb top: its cross-section
// (gutter pan, vertical, sloped or rolled face, top), how its height varies along the road, and where
// it is cut for driveways, crosswalk ramps and curbless stretches. The band is meshed explicitly, a
// cross-section every half metre; the raised ground behind it (sidewalks, ramps, verges) continues
// from its top.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim/road_surface.hpp"
#include "sim/triangle_mesh.hpp"
#include "sim/world_description.hpp"

namespace lidarloop {

struct PointsKdTree;

// The face of a curb seen in cross-section: it rises `height` over a horizontal run.
double face_run(CurbProfile profile, double height);
// Height of the face above its foot at fraction u in [0, 1] of its run (u = 1 is the top).
double face_rise(CurbProfile profile, double u);

const char* curb_profile_name(CurbProfile profile);

// A stretch of one side of a road where the curb is cut, in arc length along the road's centreline.
struct CurbCutSpan {
  double from, to;
  CurbCut kind;
};
// Every cut of one side (left or right) of road number `road`: those the world file lists, a ramp at
// each crosswalk (when the world builds them), and driveways at the road's spacing clear of the others.
std::vector<CurbCutSpan> curb_cuts_of(const WorldDescription& d, int road, RoadSide side);
const char* curb_cut_name(CurbCut cut);

// One cross-section of the band, at a point of a curb line.
struct CurbStation {
  Eigen::Vector2d point;   // the curb line: the carriageway's edge, where the face starts
  Eigen::Vector2d normal;  // unit, away from the carriageway
  double miter = 1;        // offsets along `normal` are scaled by this to stay parallel to the line
  int road = -1;           // the road whose curb this is
  double s = 0;            // arc length along that road's centreline
  CurbProfile profile = CurbProfile::vertical;
  double nominal_height = 0;   // the curb's reveal here without any cut, m
  double height = 0;           // as built: 0 inside a cut, tapering over the flares
  std::optional<CurbCut> cut;  // set where the curb is fully cut
  double gutter_width = 0, gutter_slope = 0;
  double sidewalk_width = 0;
  double bottom_z = 0;   // the face's foot (the gutter's low edge)
  double terrain_z = 0;  // the terrain's height at `point`
};

// The band's widths, the same along every curb so the regions beside it can be cut once: it spans
// `inner` metres into the carriageway (the widest gutter) and `outer` metres behind the curb line
// (the widest face plus the curb's top).
struct CurbBandWidths {
  double inner = 0, outer = 0;
};
CurbBandWidths curb_band_widths(const WorldDescription& description);

// Cross-sections along each ring of the carriageway's edge (Clipper rings: carriageway on the left),
// at most `step` apart.
std::vector<std::vector<CurbStation>> curb_stations(const std::vector<Polyline2d>& rings,
                                                    const WorldDescription& description, const RoadSurface& surface,
                                                    double step);

// The ring offset by `offset` metres along the stations' normals (negative: into the carriageway),
// closed, as the boundary of the regions beside the band.
Polyline2d offset_ring(const std::vector<CurbStation>& ring, double offset);

// Height of the raised ground (curb tops, ramps, sidewalks, verges) anywhere behind the band: the
// curb top of the nearest cross-sections, rising to the uncut sidewalk level at the ramp slope and
// away from the road at the sidewalk's cross-slope, and following the terrain.
class RaisedGround {
 public:
  RaisedGround(std::vector<std::vector<CurbStation>> rings, std::shared_ptr<const RoadSurface> surface,
               const WorldGeometryParams& geometry, double band_outer);
  ~RaisedGround();
  double operator()(const Eigen::Vector2d& p) const;
  const std::vector<std::vector<CurbStation>>& rings() const { return rings_; }

 private:
  double from_station(const CurbStation& c, const Eigen::Vector2d& p) const;
  std::vector<std::vector<CurbStation>> rings_;
  std::vector<const CurbStation*> flat_;
  std::vector<Eigen::Vector2d> points_;
  std::unique_ptr<PointsKdTree> index_;
  std::shared_ptr<const RoadSurface> surface_;
  double sidewalk_cross_slope_, ramp_slope_, band_outer_;
};

// Triangles of the band: pavement up to each gutter's lip, gutter pan, curb face and top.
void mesh_curb_band(const RaisedGround& raised, const RoadSurface& surface, CurbBandWidths widths, MaterialId pavement,
                    MaterialId concrete, TriangleMesh& mesh);

// The curb lines of the map: each ring split where its kind changes (a profile, or a cut's kind), with
// the kind of each line.
void curb_lines(const std::vector<std::vector<CurbStation>>& rings, std::vector<Polyline2d>& lines,
                std::vector<std::string>& kinds);

}  // namespace lidarloop
