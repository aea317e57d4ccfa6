#pragma once
// An ASAM OpenDRIVE map (`.xodr`, versions 1.4 to 1.8: what CARLA, esmini, RoadRunner and the OSM
// converters write), read into plain structs. Coordinates stay as the file gives them: the map's own
// x / y (east / north, metres) and the road coordinates s (along the reference line) and t (left of
// it); sim/opendrive_geometry.hpp evaluates them. Nothing is dropped: what the world does not build is
// still here, for its report.
//
// The file's `header/geoReference` is a PROJ string. Its `+lat_0` / `+lon_0` are the origin of the map's
// x / y (CARLA writes only those: a transverse Mercator about them, the projection this project's local
// frame uses too). A missing string, one without lat_0 / lon_0, or one at 0 / 0 is a placeholder: the
// origin is then the world file's, and the map says so in its warnings.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/geodetic.hpp"

namespace lidarloop {

// a + b ds + c ds^2 + d ds^3, ds from `s` (a record's start: s, sOffset or the lane section's start).
struct OdrCubic {
  double s = 0, a = 0, b = 0, c = 0, d = 0;
  double at(double s_abs) const {
    const double ds = s_abs - s;
    return a + ds * (b + ds * (c + ds * d));
  }
  double slope(double s_abs) const {
    const double ds = s_abs - s;
    return b + ds * (2 * c + ds * 3 * d);
  }
};
// Records in order of s; the value at s is the last record starting at or before it (0 before the first).
double odr_piecewise(const std::vector<OdrCubic>& records, double s);

enum class OdrGeometryKind { line, arc, spiral, poly3, param_poly3 };

// One `planView/geometry`: a piece of the reference line starting at (x, y) heading hdg.
struct OdrGeometry {
  OdrGeometryKind kind = OdrGeometryKind::line;
  double s = 0, x = 0, y = 0, hdg = 0, length = 0;
  double curvature = 0;                   // arc
  double curv_start = 0, curv_end = 0;    // spiral (clothoid: curvature linear in s)
  double a = 0, b = 0, c = 0, d = 0;      // poly3: v = a + b u + c u^2 + d u^3 in the local u / v frame
  double au = 0, bu = 0, cu = 0, du = 0;  // paramPoly3: u(p), v(p)
  double av = 0, bv = 0, cv = 0, dv = 0;
  bool normalized = true;  // paramPoly3 pRange: p in [0, 1] ("normalized", the default) or [0, length]
};

// A `height` record: the lane's surface above the road's, at its inner and outer edge, from sOffset on.
struct OdrLaneHeight {
  double s_offset = 0, inner = 0, outer = 0;
};

// One `<line>` of a road mark's explicit `<type>`: a stripe `length` long every length + space,
// shifted t_offset across the lane's edge (left positive) and s_offset along it.
struct OdrMarkLine {
  double length = 0, space = 0, t_offset = 0, s_offset = 0, width = 0;
};

struct OdrRoadMark {
  double s_offset = 0;             // from the lane section's start
  std::string type = "none";       // solid, broken, solid solid, solid broken, broken solid, broken broken,
                                   // botts dots, grass, curb, edge, custom, none
  std::string weight;              // standard, bold ("" when absent)
  std::string color;               // standard, white, yellow, ...
  std::optional<double> width;     // m
  std::vector<OdrMarkLine> lines;  // the explicit pattern, when the mark gives one
  // laneChange: "increase" (allowed towards the larger lane id), "decrease", "both", "none"; "" when the
  // mark does not say (then its type says).
  std::string lane_change;
};

struct OdrLane {
  int id = 0;                    // > 0 left of the reference line, < 0 right, 0 the centre lane
  std::string type = "none";     // driving, sidewalk, border, shoulder, curb, parking, biking, median, ...
  bool level = false;            // kept level: superelevation does not tilt it
  std::vector<OdrCubic> width;   // s of each = sOffset from the section's start
  std::vector<OdrCubic> border;  // the lane's outer edge's |t| from the offset reference line instead of width
  std::vector<OdrLaneHeight> height;
  std::vector<OdrRoadMark> marks;
  std::optional<int> predecessor, successor;  // lane ids in the linked road or section
  int line = 0;                               // in the file, for later messages
};

struct OdrLaneSection {
  double s = 0;
  std::vector<OdrLane> left, right;  // left: ids 1, 2, ... (inner first); right: -1, -2, ...
  OdrLane center;
  const OdrLane* lane(int id) const;
};

struct OdrLink {
  std::string element_type;  // road, junction
  std::string element_id;
  std::string contact_point;  // start, end ("" for a junction)
};

struct OdrCorner {
  double u = 0, v = 0, z = 0, height = 0;  // cornerLocal: object frame; cornerRoad: u = s, v = t, z = dz
  bool road_frame = false;
};

struct OdrObject {
  std::string id, type, name;  // type: crosswalk, parkingSpace, pole, building, ... (1.4: subtype in name)
  double s = 0, t = 0, z_offset = 0, hdg = 0;
  double length = 0, width = 0, radius = 0, height = 0;
  std::vector<std::vector<OdrCorner>> outlines;
  int line = 0;
};

struct OdrRoad {
  std::string id, name, junction = "-1";  // junction: "-1" for a road outside any
  // rule="LHT" (OpenDRIVE 1.5+): the lanes left of the reference line are driven along s. Right-hand
  // traffic (the right lanes along s) where the road does not say.
  bool left_hand_traffic = false;
  double length = 0;
  std::optional<OdrLink> predecessor, successor;
  std::string type;  // the first `type` record's type (town, rural, motorway, ...)
  std::vector<OdrGeometry> plan_view;
  std::vector<OdrCubic> elevation;       // z of the reference line
  std::vector<OdrCubic> superelevation;  // roll angle about the reference line, rad, positive: right side down
  std::vector<OdrCubic> lane_offset;     // t of the centre lane
  std::vector<OdrLaneSection> sections;
  std::vector<OdrObject> objects;
  int signals = 0;  // read, not built
  int line = 0;
  // Index of the section that holds s.
  size_t section_at(double s) const;
  double section_end(size_t i) const { return i + 1 < sections.size() ? sections[i + 1].s : length; }
  // Whether lane `lane_id` is driven in the direction of increasing s.
  bool along_s(int lane_id) const { return (lane_id < 0) != left_hand_traffic; }
};

struct OdrLaneLink {
  int from = 0, to = 0;
};

struct OdrConnection {
  std::string id, incoming_road, connecting_road, contact_point;
  std::vector<OdrLaneLink> lane_links;
};

struct OdrJunction {
  std::string id, name;
  std::vector<OdrConnection> connections;
};

struct OdrMap {
  std::string file;
  int rev_major = 1, rev_minor = 4;
  std::string geo_reference;  // the PROJ string as written
  Geodetic origin;            // of the map's x / y
  bool origin_from_map = false;
  std::vector<OdrRoad> roads;
  std::vector<OdrJunction> junctions;
  std::map<std::string, size_t> road_index;  // id -> index into roads
  std::vector<std::string> warnings;

  const OdrRoad* road(const std::string& id) const;
};

struct OdrReadOptions {
  // The world file's origin: used where the map's geoReference is a placeholder, and in place of it
  // when `override_origin` is set.
  std::optional<Geodetic> origin;
  bool override_origin = false;
  // Roads farther than this from the map's origin are taken for a broken file.
  double max_extent_m = 50'000;
};

// Reads `path`. Throws InputError, one line "FILE:LINE: road ID at s=S: what", for a file that is not
// XML or not OpenDRIVE, an unknown geometry, a link or junction connection to a missing road, a lane
// width that goes negative, a paramPoly3 or poly3 that folds back, a road without geometry or lanes.
OdrMap read_opendrive(const std::string& path, const OdrReadOptions& options = {});
// The same from text in memory.
OdrMap parse_opendrive(const std::string& xml, const std::string& name, const OdrReadOptions& options = {});

}  // namespace lidarloop
