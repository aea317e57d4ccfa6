#pragma once
// A top view of the survey for people: every lane the mapping drive followed, coloured by the size of
// the survey's position error there, over the world's curbs (grey), north up, with a colour bar.
#include <string>

#include "mapping/survey_map.hpp"
#include "sim/world_builder.hpp"

namespace lidarloop {

// The longer side of the picture is at most max_pixels (cells of at least min_metres_per_pixel).
void write_survey_error_png(const std::string& path, const World& world, const SurveyDrive& survey,
                            double min_metres_per_pixel = 0.5, int max_pixels = 3000);

}  // namespace lidarloop
