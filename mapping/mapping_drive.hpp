#pragma once
// The mapping drive: a simulated survey car drives every lane of every road (both directions on
// two-way roads) and accumulates the intensities of ground returns into the intensity layer, as a
// survey vehicle does before a localizer can run. The map is a survey, not the world: each scan is
// placed with the pose the survey car's RTK-INS reports (the truth plus mapping/survey_error.hpp's error),
// and the survey car's HDL-32E is another unit than the test car's, with its own per-laser gains. The
// same drive, if asked, builds the point-cloud layer (localizer/point_map.hpp): every return within
// max_range, placed with the survey pose of its own firing (de-skewed), one centroid per voxel.
#include <functional>
#include <random>
#include <string>

#include "common/yaml_reader.hpp"
#include "localizer/intensity_map.hpp"
#include "localizer/point_map.hpp"
#include "mapping/curb_label.hpp"
#include "mapping/survey_map.hpp"
#include "sim/materials.hpp"
#include "sim/realism.hpp"
#include "sim/street_use.hpp"
#include "sim/traffic.hpp"
#include "sim/world_assets.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

struct MappingOptions {
  bool traffic = false;     // oncoming vehicles on the mapped roads (they raise cell variance)
  double speed = 15.0;      // m/s along each lane: 1.5 m between scans of 40 m reach
  double resolution = 0.2;  // m per cell
  int tile_cells = 320;     // 64 m tiles at 0.2 m
  // m above the carriageway: asphalt, paint, curbs and sidewalks, and the low parts of vehicles passing
  // by, which is how traffic raises the variance of the cells it crosses (paper, section 2.2.2).
  double max_ground_height = 0.5;
  double max_range = 40.0;  // m: farther ground returns are too sparse to help
  uint64_t seed = 1;        // the LiDAR's noise and the survey error
  SurveyErrorConfig survey_error;
  // How the curb layer is drawn from the survey (mapping/curb_label.hpp): the world's line by default.
  CurbLabelConfig curb_label;
  // The survey car's HDL-32E (Hdl32eConfig::unit_serial): another unit than the test car's, whose
  // default serial is 1, so the map's per-laser intensity gains are not the scans'.
  uint64_t survey_unit_serial = 2;
  // Map the world on ideal ground (flat roads, ideal curbs: on_ideal_ground), as the `ideal` profile's
  // car drives it.
  bool ideal_ground = false;
  // The markings' wear on the survey day (sim/paint_wear.hpp): a scenario's `paint`, as it was before
  // the changes the drive day shows.
  PaintConfig paint;
  // Vehicles parked along the streets on the survey day (survey_day_parking), which the survey saw
  // as it sees the world: they hide the road under and behind them from the intensity layer, and stand
  // in the point layer. Empty: nobody parked.
  std::vector<ActorPlan> parked;
  // Whether a scenario's street parking (`street.parking`) was also there, with other cars, on the
  // survey day (read_survey_options' `parked_on_survey_day`; used by survey_day_parking's callers).
  bool parked_on_survey_day = true;
  // The point-cloud layer's voxel, m: one point (the centroid) per voxel. 0.4 m keeps the surfaces a
  // GICP needs (curb faces, walls, poles of 0.1-0.3 m are one voxel thick) at about a quarter of the
  // points of 0.2 m, and divides the intensity tiles' 64 m into whole voxels (160), so both layers
  // share one tile grid. GICP's own scan voxel is coarser still (GicpParams::scan_voxel_m).
  double point_voxel_m = 0.4;
  // Every this many survey scans feed the point layer: 4 is 6 m apart at 15 m/s, so a surface within
  // the 40 m range is still seen from a dozen places, while the layer costs a quarter of the time
  // (each return is a hash-table update; the intensity layer takes every scan).
  int point_scan_stride = 4;

  std::string describe() const;  // every option as text, for the cache key and the map header
};

// The mapping options of a realism profile (sim/realism.hpp): the `typical` map is the defaults above (an
// RTK-INS survey by another HDL-32E unit); `ideal` is the world itself (no pose error, the test car's own
// unit, ideal ground); `harsh` is a map made without RTK, a GNSS-anchored SLAM map with labelling noise
// (see mapping_drive.cpp for the figures).
MappingOptions mapping_options_for(Realism realism);

// The world a map with these options is built from: the world file, on ideal ground if options say so,
// with the paint of the survey day.
LoadedWorld load_mapped_world(const std::string& world, const MappingOptions& options);

// Overrides of the survey settings from a YAML mapping: unit_serial, provenance (rtk_ins or slam; the
// other keys then override that provenance's figures), sigma_xy_m, correlation_length_m,
// heading_sigma_deg, heading_correlation_length_m (rtk_ins), slam_absolute_m, slam_relative_m,
// slam_relative_over_m (slam), sample_spacing_m, curb_label (face_foot, face_top or gutter_line),
// label_noise_m, label_noise_correlation_m, parked_on_survey_day.
void read_survey_options(const YamlReader& yaml, const YAML::Node& node, MappingOptions& options);

// The street parking of `parking` as it was on the survey day: the same stretches and occupancy, the
// cars drawn for another day (from `mapping_seed`, not the scenario's seed, so one map serves every
// seed of a scenario and the drive day's cars are not the survey day's).
std::vector<ActorPlan> survey_day_parking(const ParkingConfig& parking, const WorldDescription& description,
                                          uint64_t mapping_seed);

// The survey the mapping drive with these options makes: its lanes and its error, drawn from an engine
// seeded with options.seed (the same every time for the same options).
SurveyDrive mapping_survey(const WorldDescription& description, const MappingOptions& options);

// The surveyed curb layer: the world's curbs densified to the survey's sample spacing, drawn to the
// labelling convention with its noise (label_curb_map, from an engine of its own seeded with
// options.seed, so the survey's draws do not change with the labelling), and moved by the survey error
// (survey_curb_map).
CurbMap surveyed_curbs(const World& world, const SurveyDrive& survey, const MappingOptions& options);

// `world_hash` identifies what the map is built from (see map_cache.hpp); it goes into the header.
// The lanes are driven in parts of a few scans, cast in parallel (TBB) and merged into the map in a fixed
// order (by place, then lane), so the map's bytes are the same at any thread count. This one keeps the
// whole map in memory: for small worlds.
IntensityMapBuilder run_mapping_drive(const WorldDescription& description, const World& world,
                                      const MaterialTable& materials, const std::string& actors_dir,
                                      const MappingOptions& options, const std::string& world_hash,
                                      const std::function<void(double fraction)>& progress = {});

// A tile of the map that no later part of the drive can reach, handed over to be written (the same
// tiles and cells as the in-memory drive's, each handed over once; `cells` may be moved from).
using FinishedTile = std::function<void(const IntensityMapHeader& header, const std::pair<int, int>& key,
                                        std::vector<IntensityMoments>& cells)>;

// The same drive, holding only the tiles still open (a few columns of tiles): each finished tile goes
// to `finished`. Returns the map's header, listing every tile.
IntensityMapHeader run_mapping_drive(const WorldDescription& description, const World& world,
                                     const MaterialTable& materials, const std::string& actors_dir,
                                     const MappingOptions& options, const std::string& world_hash,
                                     const FinishedTile& finished,
                                     const std::function<void(double fraction)>& progress = {},
                                     PointMapWriter* points = nullptr);
// `points`, if given, receives the point-cloud layer tile by tile, finished with its header.

}  // namespace lidarloop
