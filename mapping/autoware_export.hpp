#pragma once
// `lidarloop map WORLD --export autoware DIR`: a built HD map as the folder Autoware's map launch
// (autoware_launch map.launch.xml, `map_path:=DIR`) loads, under its default file names:
//   pointcloud_map.pcd       the survey's point cloud layer (localizer/point_map.hpp: the mapping drive's
//                            scans placed with the survey poses, one centroid per voxel), re-voxelized
//                            to `voxel_m`, as binary PCD with fields x y z intensity (float32, the
//                            layout of pcl::PointXYZI) that Autoware's pointcloud_map_loader reads with
//                            PCL: NDT registers against x y z, intensity is for display;
//   lanelet2_map.osm         the vector map (mapping/lanelet2_map.hpp);
//   map_projector_info.yaml  how Autoware turns lat/lon into the map frame (autoware_map_projection_loader).
// No pointcloud_map_metadata.yaml: that is for a point cloud divided into several files, and one file
// loads without it. No map_config.yaml either: the map loaders' parameters (leaf sizes, projector
// options) come from autoware_launch's config/map/*.param.yaml, not from the map folder.
#include <cstddef>
#include <string>

#include "mapping/lanelet2_map.hpp"
#include "mapping/mapping_drive.hpp"

namespace lidarloop {

struct AutowareExportConfig {
  // Voxel of pointcloud_map.pcd, m: the point layer's own 0.4 m (MappingOptions::point_voxel_m) by
  // default, which Autoware's NDT needs no finer: ndt_scan_matcher fits one normal distribution per
  // `resolution` = 2 m cell (its default), and 0.4 m leaves over a hundred map points in a cell full of
  // surface. Coarser values shrink the file; finer ones than the layer's cannot be made from it.
  double voxel_m = 0.4;
};

struct AutowareExportSummary {
  std::string dir;
  size_t points = 0;
  Lanelet2Summary lanelet2;
};

// The default file names of Autoware's map launch (autoware_launch map.launch.xml arguments
// pointcloud_map_file, lanelet2_map_file, map_projector_info_file).
inline constexpr const char* kAutowarePointCloudFile = "pointcloud_map.pcd";
inline constexpr const char* kAutowareLanelet2File = "lanelet2_map.osm";
inline constexpr const char* kAutowareProjectorFile = "map_projector_info.yaml";

// Exports the map in `map_dir` (built by ensure_map from `world` with `options`) to `out_dir`, which is
// made if missing. InputError naming the folder or file that cannot be written, or a voxel finer than
// the point layer's.
AutowareExportSummary export_autoware_map(const std::string& world, const MappingOptions& options,
                                          const std::string& map_dir, const std::string& out_dir,
                                          const AutowareExportConfig& config = {});

}  // namespace lidarloop
