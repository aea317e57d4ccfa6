#include "mapping/autoware_export.hpp"

#include <bit>
#include <filesystem>
#include <sstream>

#include "common/input_error.hpp"
#include "common/little_endian.hpp"
#include "common/output_dir.hpp"
#include "localizer/intensity_map.hpp"
#include "localizer/map_files.hpp"
#include "localizer/point_map.hpp"
#include "logs/pcd_file.hpp"
#include "mapping/survey_map.hpp"

namespace lidarloop {

namespace {

// The point layer re-voxelized, every point with the intensity layer's mean under it where it is
// ground (at most max_ground_height above the pavement: what that layer accumulates) and 0 elsewhere
// (the point layer keeps no intensity). z is the WGS-84 ellipsoidal height, the origin's altitude plus the
// local z, as the Lanelet2 map's ele (map_projector_info.yaml declares vertical_datum WGS84). Points in tile
// order, then voxel order: the same bytes every time.
size_t write_point_cloud(const std::string& path, const std::string& map_dir, const World& world,
                         const MappingOptions& options, double voxel_m) {
  const PointMapHeader layer = read_point_map_header(map_dir);
  if (!(voxel_m >= layer.voxel_m))
    throw InputError(map_dir + ": the point layer's voxel is " + shortest_decimal(layer.voxel_m) +
                     " m; the export's cannot be finer (asked " + shortest_decimal(voxel_m) + " m)");
  PointMapHeader header;
  header.world = layer.world;
  header.world_hash = layer.world_hash;
  header.voxel_m = voxel_m;
  header.tile_voxels = std::max(1, int(std::lround(layer.tile_size_m() / voxel_m)));
  PointMapBuilder voxels(header);
  for (const auto& key : layer.tiles)
    for (const Eigen::Vector3f& p : read_point_tile(point_tile_file(map_dir, key), key)) voxels.add(p.cast<double>());

  IntensityMap intensity(map_dir);
  const GroundHeight pavement = world.pavement();
  std::string body;
  size_t count = 0;
  const std::vector<std::pair<int, int>> tiles = voxels.header().tiles;  // take_tile changes the builder
  for (const auto& key : tiles)
    for (const Eigen::Vector3f& p : voxels.take_tile(key)) {
      const Eigen::Vector2d xy = p.head<2>().cast<double>();
      float value = 0;
      if (p.z() - pavement(xy) <= options.max_ground_height)
        if (const auto cell = intensity.cell(xy)) value = cell->mean;
      const float z = float(double(p.z()) + world.origin.alt_m);
      for (const float v : {p.x(), p.y(), z, value}) append_le(body, std::bit_cast<uint32_t>(v), 4);
      ++count;
    }
  const std::string head = binary_pcd_header({{"x"}, {"y"}, {"z"}, {"intensity"}}, count,
                                             "lidarloop point cloud map of " + layer.world + ", local metres");
  write_file_atomically(path, head + body);
  return count;
}

// autoware_map_projection_loader's map_projector_info.yaml. Our local frame is a transverse Mercator
// projection on the origin's meridian with scale 1, northing from the origin's (common/geodetic.hpp),
// which is Autoware's TransverseMercator projector (autoware_lanelet2_extension
// transverse_mercator_projector.cpp: central meridian = map_origin.longitude, y less the origin's
// northing) given scale_factor 1.0; its default 0.9996 (autoware_map_msgs MapProjectorInfo) would
// shrink every distance by 0.04 %. Heights: vertical_datum WGS84 says the map frame's z is the WGS-84
// ellipsoidal height, which Autoware's projector passes through from the GNSS fix's altitude
// (autoware_geography_utils project_forward: z = altitude); so ele and the point cloud's z are the
// origin's altitude (taken as ellipsoidal, as the world file gives it) plus the local height.
void write_projector_info(const std::string& path, const Geodetic& origin) {
  std::ostringstream y;
  y << "# How Autoware's map_projection_loader turns latitude and longitude into this map's frame.\n"
    << "# x, y: metres east and north of map_origin on its transverse Mercator (scale 1). z (the point\n"
    << "# cloud's z, the Lanelet2 map's ele): WGS-84 ellipsoidal height, map_origin.altitude plus the\n"
    << "# height above it.\n"
    << "projector_type: TransverseMercator\n"
    << "vertical_datum: WGS84\n"
    << "scale_factor: 1.0\n"
    << "map_origin:\n"
    << "  latitude: " << shortest_decimal(origin.lat_deg) << "\n"
    << "  longitude: " << shortest_decimal(origin.lon_deg) << "\n"
    << "  altitude: " << shortest_decimal(origin.alt_m) << "\n";
  write_file_atomically(path, y.str());
}

}  // namespace

AutowareExportSummary export_autoware_map(const std::string& world, const MappingOptions& options,
                                          const std::string& map_dir, const std::string& out_dir,
                                          const AutowareExportConfig& config) {
  prepare_output_dir(out_dir);
  const LoadedWorld w = load_mapped_world(world, options);
  AutowareExportSummary summary;
  summary.dir = out_dir;
  summary.points =
      write_point_cloud(out_dir + "/" + kAutowarePointCloudFile, map_dir, w.world, options, config.voxel_m);
  const SurveyDrive survey = mapping_survey(w.description, options);
  const SurveyedLine surveyed = [&](const Polyline2d& line) {
    const CurbMap one{w.world.origin, w.world.name, {line}, {}};
    return survey_curb_map(densify_curb_map(one, options.survey_error.sample_spacing_m), survey).curbs.front();
  };
  // The map's version is the world's hash the map was built from: a changed world is a new map version.
  summary.lanelet2 = write_lanelet2_map(out_dir + "/" + kAutowareLanelet2File, w.description, w.world,
                                        read_curb_map(map_dir + "/curbs.geojson"), surveyed,
                                        read_point_map_header(map_dir).world_hash);
  write_projector_info(out_dir + "/" + kAutowareProjectorFile, w.world.origin);
  return summary;
}

}  // namespace lidarloop
