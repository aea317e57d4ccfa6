#pragma once
// Worn paint (scenario section `paint:`): each road marking's retroreflectivity drawn from what roads
// have, worn patches where the paint is gone to the asphalt, the LiDAR reflectivity that follows the
// retroreflectivity loosely, and markings faded further or re-painted between the survey and the drive.
//
// `typical`: worn paint with the sourced campus figures below (the defaults); `ideal`: uniform paint,
// every marking its material's reflectivity (`paint: {varied: false}` in any profile); `harsh`: worn
// paint near the end of its life (paint_config_for).
//   varied             bool      true   true: worn paint as below; false: uniform (nothing below applies)
//   retro_mean_mcd     mcd/m2/lx 162.5  mean retroreflectivity of a marking
//   retro_sigma_mcd    mcd/m2/lx 43.75  its spread between markings (1 sigma)
//   retro_min_mcd      mcd/m2/lx 75     floor: a marking below it would have been re-painted
//   material_retro_mcd mcd/m2/lx 162.5  the marking whose reflectivity is its material's (assets/materials.yaml)
//   intensity_r2       0..1      0.75   R^2 of the LiDAR reflectivity against the retroreflectivity
//   segment_m          m         10     a long line draws one retroreflectivity per this length
//   worn_fraction      0..1      0.10   share of each marking's area worn to the asphalt
//   faded_fraction     0..1      0.10   drive day: share of markings faded further since the survey
//   fade_factor        0..1      0.5    drive day: a faded marking keeps this share of its retroreflectivity
//   repainted_fraction 0..1      0.05   drive day: share of markings re-painted since the survey
//   repaint_mcd        mcd/m2/lx 250    a re-painted marking's retroreflectivity (and no worn patches)
//   seed               integer   1      the world's paint: the same for the survey and the drive
//
// Every draw is a pure function of the seed and the marking's place (counter-based, sim/counter_rng.hpp),
// so the survey's world and the drive's world, built apart, agree on every marking they share, the
// same seed gives the same world byte for byte, and markings added or removed elsewhere (a scenario's
// world_changes) change no other marking's draw.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/yaml_reader.hpp"
#include "sim/counter_rng.hpp"
#include "sim/materials.hpp"
#include "sim/realism.hpp"

namespace lidarloop {

struct PaintConfig {
  // Worn paint with the campus figures below: `typical`'s. `ideal` sets it false: every marking its
  // material's reflectivity (uniform, new paint).
  bool varied = true;
  // Retroreflectivity R_L of dry white markings, mcd/m2/lx. New markings: at least 250 (ASTM D6359,
  // the common specification for new white markings); maintained minimum: 50-100 (FHWA's minimum
  // retroreflectivity rule, MUTCD 2009 Rev. 3 section 3A.03, 2022: 50 at 35 mph and above, 100 at 70
  // mph and above; taken as its middle, 75). A campus's markings lie between: the mean is the middle of
  // 75 and 250, and the sigma puts those two 2 sigma either side of it (assumption: no campus survey at
  // hand). A draw below the floor is set to it: such a marking would have been re-painted.
  double retro_mean_mcd = 162.5;
  double retro_sigma_mcd = 43.75;
  double retro_min_mcd = 75;
  // The marking that shows its material's reflectivity (assets/materials.yaml): the typical mean, so
  // that `typical` paint is as bright on average as the uniform paint was. The reflectivity is in
  // proportion to R_L (a linear fit through the origin: assumption; the studies below fit lines).
  double material_retro_mcd = 162.5;
  // Mobile LiDAR intensity against measured R_L, linear fits: R^2 0.87 on edge lines and 0.63 on skip
  // lines (Mahlberg et al. 2021, Future Transp. 1(3):720-736, 70 miles of US-52/US-41); 0.82 from a
  // VLP-32C with a learnt model (Univ. of Cincinnati, Buildings 2024, 14(1):62). Taken as the middle of
  // 0.63-0.87: 0.75. The scatter is per marking (dirt, bead embedment), drawn once.
  double intensity_r2 = 0.75;
  // A long line is laid and worn in stretches: one draw per 10 m of it (assumption: about one dash
  // period, 3 m dash and 6 m gap; retroreflectometer surveys average over longer stretches).
  double segment_m = 10;
  // Share of a marking's area worn to the asphalt, in patches of one paint piece (0.5 m): assumption
  // (ASTM D913 rates wear as the share of paint left; no campus figure found). Wheel paths are not
  // modelled apart: the patches fall anywhere on a marking.
  double worn_fraction = 0.10;
  // Between the survey and the drive (a map some months old): assumptions. Faded: a tenth of markings
  // lost half their R_L; re-painted: a twentieth of markings laid new, at ASTM D6359's 250.
  double faded_fraction = 0.10;
  double fade_factor = 0.5;
  double repainted_fraction = 0.05;
  double repaint_mcd = 250;
  uint64_t seed = 1;

  // What the survey day's paint depends on (every key but the drive day's changes), for a map's cache
  // key; empty for uniform paint, so the maps made before this knob keep their keys.
  std::string describe_survey() const;
};

// ideal: uniform; typical: the defaults; harsh: markings near the end of their life.
PaintConfig paint_config_for(Realism realism);

// Applies the overrides in a YAML mapping (keys as the field names) and validates the result.
void read_paint_config(const YamlReader& yaml, const YAML::Node& node, PaintConfig& config);

// Which day's paint a world shows: the survey's (the map) or the drive's (today, with the changes).
enum class PaintDay { survey, drive };

struct PaintConditions {
  PaintConfig config;
  PaintDay day = PaintDay::drive;
};

// The engines the paint is drawn from, one stream per kind of draw, seeded by the config's seed.
struct PaintRng {
  explicit PaintRng(uint64_t seed);
  CounterRng retro, scatter, wear, change;
};

// One marking's look: its retroreflectivity, the LiDAR reflectivity that goes with it, and whether it
// was re-painted since the survey (then it has no worn patches).
struct MarkingLook {
  double retro_mcd = 0;
  double reflectivity = 0;
  bool repainted = false;
};

// The key of a marking (or of a piece of one) from its place: centimetre-rounded coordinates and an
// index (a long line's stretch).
uint64_t marking_key(const Eigen::Vector2d& place, uint64_t index = 0);

// The marking with key `key`, of a material whose reflectivity is `material_reflectivity`.
MarkingLook draw_marking(const PaintConfig& config, PaintDay day, const PaintRng& rng, double material_reflectivity,
                         uint64_t key);
// Whether the piece of paint with key `key` is worn to the asphalt.
bool worn_piece(const PaintConfig& config, const PaintRng& rng, uint64_t key);

// What the world builders ask of the paint as they lay it: each marking's material (a variant of the
// paint's material with the marking's reflectivity, kept in `variants`) and which of its pieces are
// worn away. Without conditions every marking is its material and nothing is worn (uniform paint).
class MarkingPainter {
 public:
  // Variants get the ids after the table's own (materials.size(), ...); the world appends them to it.
  MarkingPainter(const std::optional<PaintConditions>& conditions, const MaterialTable& materials);

  bool uniform() const { return !conditions_; }
  double segment_m() const { return conditions_ ? conditions_->config.segment_m : 0; }
  // The material of the marking of `base` material keyed by `key`; `fresh` tells whether it was
  // re-painted (no worn patches).
  MaterialId marking(MaterialId base, uint64_t key, bool& fresh);
  // Whether the piece of paint centred at `centre` is worn away (never on a fresh marking).
  bool worn(const Eigen::Vector2d& centre, bool fresh) const;
  // The variants made so far: material ids table.size(), table.size() + 1, ...
  const std::vector<Material>& variants() const { return variants_; }

 private:
  std::optional<PaintConditions> conditions_;
  PaintRng rng_;
  const MaterialTable& materials_;
  std::vector<Material> variants_;
  std::map<std::pair<MaterialId, int>, MaterialId> variant_ids_;  // (base, reflectivity in steps) -> id
};

}  // namespace lidarloop
