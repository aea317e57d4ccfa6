#include "common/geodetic.hpp"

#include <GeographicLib/Constants.hpp>

namespace lidarloop {

LocalFrame::LocalFrame(const Geodetic& origin)
    : origin_(origin), projection_(GeographicLib::Constants::WGS84_a(), GeographicLib::Constants::WGS84_f(), 1.0) {
  double easting = 0;
  projection_.Forward(origin.lon_deg, origin.lat_deg, origin.lon_deg, easting, origin_northing_);
}

Eigen::Vector2d LocalFrame::to_local(double lat_deg, double lon_deg) const {
  double x = 0, y = 0;
  projection_.Forward(origin_.lon_deg, lat_deg, lon_deg, x, y);
  return {x, y - origin_northing_};
}

Geodetic LocalFrame::to_geodetic(const Eigen::Vector2d& xy, double alt_m) const {
  Geodetic g;
  projection_.Reverse(origin_.lon_deg, xy.x(), xy.y() + origin_northing_, g.lat_deg, g.lon_deg);
  g.alt_m = alt_m;
  return g;
}

}  // namespace lidarloop
