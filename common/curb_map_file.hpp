#pragma once
// The curb map on disk: a GeoJSON FeatureCollection of LineStrings in WGS-84 ([lon, lat]), which
// opens in QGIS or geojson.io. In memory the curbs are polylines in the local metric frame.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geodetic.hpp"

namespace lidarloop {

using Polyline2d = std::vector<Eigen::Vector2d>;

struct CurbMap {
  Geodetic origin;                // the local frame's origin
  std::string world;              // name of the world it was made from (may be empty)
  std::vector<Polyline2d> curbs;  // local metres
  // What each curb line is (kinds[i] for curbs[i]): vertical, sloped, rolled, or a cut (driveway,
  // ramp, flush); empty when the map does not say.
  std::vector<std::string> kinds;
};

void write_curb_map(const std::string& path, const CurbMap& map);
// Throws InputError naming the file for anything that is not a curb map.
CurbMap read_curb_map(const std::string& path);

}  // namespace lidarloop
