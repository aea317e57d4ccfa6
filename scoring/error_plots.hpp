#pragma once
// PNG plots of a scored run for people: the error curves against time (the paper's Fig. 11) and the
// trajectory coloured by position error (Fig. 13). White background, readable at about 1200 x 900.
#include <string>
#include <vector>

#include "common/curb_map_file.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {

struct PlotSize {
  int width = 1200, height = 900;  // pixels; at least 400 x 300 (smaller throws InputError)
};

// Three stacked panels sharing the time axis: lateral (m), longitudinal (m) and heading (deg) error,
// each with its RMSE in the title (over every frame drawn), tick labels, grid and a zero line; around
// zero the +-3 sigma band the estimate claims on that axis (in the truth's frame, scoring/scorer.hpp),
// on the lateral and longitudinal panels the protection bounds (dashed); `lost` stretches shaded
// across every panel, each of `events` a vertical line named at the top, and a legend.
void write_error_plot(const std::string& path, const std::vector<FrameError>& errors,
                      const std::vector<FaultEvent>& events = {}, const PlotSize& size = {});

// North up, equal aspect, framed on the trajectories: the truth trajectory drawn thin, over it the
// stretch the estimates cover coloured by position error with a colour bar, the estimate as a thin
// line, the worst frame circled, a metre scale bar. `background` (curbs, say) is drawn in light grey.
void write_trajectory_plot(const std::string& path, const std::vector<TruthPose>& truth,
                           const std::vector<EstimateRecord>& estimates, const std::vector<FrameError>& errors,
                           const std::vector<Polyline2d>& background = {}, const PlotSize& size = {});

}  // namespace lidarloop
