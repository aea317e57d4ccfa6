#pragma once
// WGS-84 <-> local metric frame (x east, y north) by a transverse Mercator projection centred on the
// map origin: the paper's "Gaussian projection" (section 2.1.1). Latitude and longitude stay in degrees,
// as in every file format that carries them; everything else is SI.
#include <Eigen/Core>
#include <GeographicLib/TransverseMercator.hpp>

namespace lidarloop {

struct Geodetic {
  double lat_deg = 0;
  double lon_deg = 0;
  double alt_m = 0;
};

class LocalFrame {
 public:
  explicit LocalFrame(const Geodetic& origin);

  const Geodetic& origin() const { return origin_; }
  // Local metres relative to the origin (scale 1 on the central meridian through the origin).
  Eigen::Vector2d to_local(double lat_deg, double lon_deg) const;
  Geodetic to_geodetic(const Eigen::Vector2d& xy, double alt_m = 0) const;

 private:
  Geodetic origin_;
  GeographicLib::TransverseMercator projection_;
  double origin_northing_ = 0;
};

}  // namespace lidarloop
