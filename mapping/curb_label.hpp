#pragma once
// The curb layer as a labeller draws it: which line of the curb's cross-section the map calls "the
// curb" (a stated convention), and how far the drawn line wanders from it (labelling noise).
//
// The world's curb lines (sim/curb_band.hpp's CurbStation::point) run along the foot of the curb face,
// the carriageway's edge: the gutter pan, if any, lies in front of it (into the carriageway), the face
// rises from it over face_run(profile, height) away from the carriageway, and the curb top follows.
// The localizer's curb detector reports the foot of the rise as well. A map drawn to another
// convention holds another line, offset from the foot by the cross-section's own widths:
//   face_foot    the foot of the face (the flow line of a gutter): offset 0, the world's line;
//   face_top     the top edge of the face, where the curb top begins: face_run(profile, height) behind
//                the foot (0 on a vertical curb, the height on a 1:1 sloped one, twice it on a rolled
//                one; 0 in a cut, where the curb is down to the road);
//   gutter_line  the gutter's lip, the seam between the asphalt and the concrete pan, the line that
//                shows in intensity and imagery: gutter_width in front of the foot (0 without a gutter).
#include <random>
#include <string>
#include <vector>

#include "common/curb_map_file.hpp"
#include "sim/curb_band.hpp"

namespace lidarloop {

enum class CurbLabel { face_foot, face_top, gutter_line };
const char* curb_label_name(CurbLabel label);

struct CurbLabelConfig {
  // Assumption (no mapping team's convention is published): a mobile-mapping survey extracts its curb
  // layer from its own scans with an automatic detector of the kind the localizer runs (the paper does
  // not say how its curb layer was made), and such a detector finds the foot of the rise.
  // Of the three lines it is also the middle one, between the gutter's lip in front and the face's top
  // behind. A map labelled by hand on a point cloud (harsh) takes the top instead.
  CurbLabel convention = CurbLabel::face_foot;
  // RMS of the drawn line's offset across the curb, m, correlated along it. Assumption, no published
  // figure found for curb polylines: 0 by default (the map's line is the convention's line exactly);
  // profiles that set it say why.
  double noise_m = 0;
  // Assumption: a labeller clicks a vertex every few metres and the line runs straight in between, so
  // the offset decorrelates over about that (a first-order Gauss-Markov process along the line).
  double noise_correlation_m = 5.0;

  bool is_default() const;
  std::string describe() const;  // every field as text, for the map cache key (empty when default)
};

// The convention's offset from the face's foot, m, positive away from the carriageway (behind the
// curb), for a cross-section of this profile, as-built height and gutter width.
double curb_label_offset(CurbLabel label, CurbProfile profile, double height, double gutter_width);

// The curbs of `map` (the world's lines, densified: mapping/survey_map.hpp's densify_curb_map) moved
// to the convention's line, each point by the offset of the nearest cross-section of `rings` (the
// world's curb band) along the line's own normal, and by the labelling noise drawn from `rng`: a
// Gauss-Markov process over the arc length of each curb, started from its stationary law. Points with
// no cross-section within a metre (a world without a curb band: Lanelet2, OpenDRIVE) keep the
// convention's offset 0. A default config gives back `map` bit for bit without drawing.
CurbMap label_curb_map(const CurbMap& map, const std::vector<std::vector<CurbStation>>& rings,
                       const CurbLabelConfig& config, std::mt19937_64& rng);

}  // namespace lidarloop
