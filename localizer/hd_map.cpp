#include "localizer/hd_map.hpp"

#include <cmath>

#include "common/input_error.hpp"

namespace lidarloop {

constexpr double kOriginTolerance = 1e-9;  // deg, ~0.1 mm: both layers must share one local frame

HdMap open_hd_map(const std::string& dir, const std::string& expected_world, size_t max_cached_tiles) {
  IntensityMap intensity(dir, max_cached_tiles);
  const std::string curbs_file = dir + "/curbs.geojson";
  CurbLayer curbs = CurbLayer::load(curbs_file);
  const IntensityMapHeader& h = intensity.header();
  const std::string header_file = dir + "/map.yaml";
  if (!expected_world.empty() && h.world != expected_world)
    throw InputError(header_file + ": this is a map of world '" + h.world + "', not of '" + expected_world + "'");
  if (curbs.map().world != h.world)
    throw InputError(curbs_file + ": curbs of world '" + curbs.map().world + "' beside an intensity layer of '" +
                     h.world + "' (" + header_file + ")");
  const Geodetic &a = curbs.map().origin, &b = h.origin;
  if (std::abs(a.lat_deg - b.lat_deg) > kOriginTolerance || std::abs(a.lon_deg - b.lon_deg) > kOriginTolerance)
    throw InputError(curbs_file + ": origin differs from the intensity layer's (" + header_file +
                     "): the layers are in different local frames");
  std::optional<PointMap> points;
  if (has_point_map(dir)) {
    points.emplace(dir, max_cached_tiles);
    if (points->header().world != h.world)
      throw InputError(dir + "/points.yaml: points of world '" + points->header().world +
                       "' beside an intensity layer of '" + h.world + "' (" + header_file + ")");
  }
  return {std::move(curbs), std::move(intensity), std::move(points)};
}

}  // namespace lidarloop
