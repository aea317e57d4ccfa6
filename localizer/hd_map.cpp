#include "localizer/hd_map.hpp"

#include <climits>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/input_error.hpp"

namespace lidarloop {

constexpr double kOriginTolerance = 1e-9;  // deg, ~0.1 mm: both layers must share one local frame

// A curb map surveyed with the intensity layer lies on the same streets, so within the extent of its
// tiles; one tile of slack is kept for a curb drawn just past the last surveyed cell. A vertex farther
// out is a curb map of another place (or a corrupt one), and densifying a line that runs off for
// hundreds of kilometres into points 10 cm apart takes seconds (222 km: 2.2 million points, 3.6 s under
// AddressSanitizer), and across a continent minutes and gigabytes, before anything could say so.
static void check_curbs_within_tiles(const CurbMap& curbs, const IntensityMapHeader& h, const std::string& curbs_file,
                                     const std::string& header_file) {
  if (h.tiles.empty()) return;
  Eigen::Vector2i lo = Eigen::Vector2i::Constant(INT_MAX), hi = Eigen::Vector2i::Constant(INT_MIN);
  for (const auto& [tx, ty] : h.tiles) {
    lo = lo.cwiseMin(Eigen::Vector2i(tx, ty));
    hi = hi.cwiseMax(Eigen::Vector2i(tx, ty));
  }
  const double tile = h.tile_size_m();
  const Eigen::Vector2d min = (lo.cast<double>().array() - 1) * tile, max = (hi.cast<double>().array() + 2) * tile;
  for (size_t i = 0; i < curbs.curbs.size(); ++i)
    for (const Eigen::Vector2d& p : curbs.curbs[i])
      if ((p.array() < min.array()).any() || (p.array() > max.array()).any()) {
        std::ostringstream msg;
        msg << std::fixed << std::setprecision(1) << curbs_file << ": feature " << i << " has a point at (" << p.x()
            << ", " << p.y() << ") m, outside the intensity layer's tiles (" << header_file << "), which span ("
            << min.x() + tile << ", " << min.y() + tile << ") to (" << max.x() - tile << ", " << max.y() - tile
            << ") m";
        throw InputError(msg.str());
      }
}

HdMap open_hd_map(const std::string& dir, const std::string& expected_world, size_t max_cached_tiles) {
  IntensityMap intensity(dir, max_cached_tiles);
  const std::string curbs_file = dir + "/curbs.geojson";
  const CurbMap curb_map = read_curb_map(curbs_file);
  const IntensityMapHeader& h = intensity.header();
  const std::string header_file = dir + "/map.yaml";
  if (!expected_world.empty() && h.world != expected_world)
    throw InputError(header_file + ": this is a map of world '" + h.world + "', not of '" + expected_world + "'");
  if (curb_map.world != h.world)
    throw InputError(curbs_file + ": curbs of world '" + curb_map.world + "' beside an intensity layer of '" + h.world +
                     "' (" + header_file + ")");
  const Geodetic &a = curb_map.origin, &b = h.origin;
  if (std::abs(a.lat_deg - b.lat_deg) > kOriginTolerance || std::abs(a.lon_deg - b.lon_deg) > kOriginTolerance)
    throw InputError(curbs_file + ": origin differs from the intensity layer's (" + header_file +
                     "): the layers are in different local frames");
  check_curbs_within_tiles(curb_map, h, curbs_file, header_file);
  CurbLayer curbs(curb_map);
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
