#pragma once
// The two charts of a sweep report: a metric's mean and spread against a varied parameter, one line per
// method, and a scatter of a metric against a measured quantity (the curb hidden), one colour per method.
#include <string>
#include <vector>

namespace lidarloop {

struct SeriesPoint {
  double x = 0, mean = 0, lo = 0, hi = 0;  // the bar spans lo..hi
};
struct Series {
  std::string name;
  std::vector<SeriesPoint> points;  // NaN means are skipped (no completed run there)
};
// `categories`: words for x = 0, 1, 2, ... (a parameter whose levels are not numbers); empty for a
// number line.
void write_series_plot(const std::string& path, const std::string& title, const std::string& x_label,
                       const std::vector<std::string>& categories, const std::vector<Series>& series);

struct ScatterSeries {
  std::string name;
  std::vector<double> x, y;
};
void write_scatter_plot(const std::string& path, const std::string& title, const std::string& x_label,
                        const std::vector<ScatterSeries>& series);

}  // namespace lidarloop
