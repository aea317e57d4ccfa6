#include "sweep/sweep_plots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "scoring/plot_canvas.hpp"

namespace lidarloop {
namespace {

using namespace plot;

constexpr int kWidth = 1000, kHeight = 650;
constexpr int kLeft = 90, kRight = 200, kTop = 50, kBottom = 70;  // the legend sits in the right margin
constexpr int kTargetXTicks = 8, kTargetYTicks = 6;
constexpr double kPadFraction = 0.08;
constexpr double kMinSpan = 1e-3;  // an all-equal metric still gets an axis
constexpr int kMarker = 4, kBarCap = 5, kLegendRow = 24;
constexpr double kCategoryPad = 0.5;  // categories sit at 0..n-1 with half a step to spare

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  // Padded, and never empty; `from_zero` keeps 0 in view (errors and rates start there).
  std::pair<double, double> padded(bool from_zero) const {
    double a = std::isfinite(lo) ? lo : 0, b = std::isfinite(hi) ? hi : 1;
    if (from_zero) a = std::min(a, 0.0);
    const double pad = std::max((b - a) * kPadFraction, kMinSpan);
    return {from_zero && a >= 0 ? a : a - pad, b + pad};
  }
};

cv::Mat canvas() { return cv::Mat(kHeight, kWidth, CV_8UC3, kWhite); }
cv::Rect area() { return {kLeft, kTop, kWidth - kLeft - kRight, kHeight - kTop - kBottom}; }

void legend(cv::Mat& image, const std::vector<std::string>& names) {
  const cv::Rect a = area();
  for (size_t k = 0; k < names.size(); ++k) {
    const cv::Point at(a.x + a.width + 20, a.y + 20 + int(k) * kLegendRow);
    cv::line(image, at, at + cv::Point(24, 0), series_colour(k), 3, cv::LINE_AA);
    text(image, names[k], at + cv::Point(32, 5));
  }
}

void x_axis_label(cv::Mat& image, const std::string& label) {
  const cv::Rect a = area();
  text(image, label, {a.x + a.width / 2, kHeight - 15}, kTitleFontScale, Align::centre);
}

}  // namespace

void write_series_plot(const std::string& path, const std::string& title, const std::string& x_label,
                       const std::vector<std::string>& categories, const std::vector<Series>& series) {
  check_size(path, kWidth, kHeight);
  cv::Mat image = canvas();
  Range xs, ys;
  for (const auto& s : series)
    for (const auto& p : s.points)
      if (std::isfinite(p.mean)) xs.add(p.x), ys.add(p.lo), ys.add(p.hi), ys.add(p.mean);
  Panel p;
  p.area = area();
  if (!categories.empty()) {
    p.x0 = -kCategoryPad, p.x1 = double(categories.size()) - 1 + kCategoryPad;
  } else {
    std::tie(p.x0, p.x1) = xs.padded(false);
  }
  std::tie(p.y0, p.y1) = ys.padded(true);
  draw_axes(image, p, title, kTargetXTicks, kTargetYTicks, categories);
  for (size_t k = 0; k < series.size(); ++k) {
    const cv::Scalar colour = series_colour(k);
    const SeriesPoint* previous = nullptr;
    for (const auto& q : series[k].points) {
      if (!std::isfinite(q.mean)) {
        previous = nullptr;  // a gap, not a line across it
        continue;
      }
      const cv::Point c = p.at(q.x, q.mean);
      cv::line(image, p.at(q.x, q.lo), p.at(q.x, q.hi), colour, 1, cv::LINE_AA);
      for (double v : {q.lo, q.hi})
        cv::line(image, p.at(q.x, v) - cv::Point(kBarCap, 0), p.at(q.x, v) + cv::Point(kBarCap, 0), colour, 1,
                 cv::LINE_AA);
      if (previous) cv::line(image, p.at(previous->x, previous->mean), c, colour, 2, cv::LINE_AA);
      cv::circle(image, c, kMarker, colour, cv::FILLED, cv::LINE_AA);
      previous = &q;
    }
  }
  std::vector<std::string> names;
  for (const auto& s : series) names.push_back(s.name);
  legend(image, names);
  x_axis_label(image, x_label);
  save_png(path, image);
}

void write_scatter_plot(const std::string& path, const std::string& title, const std::string& x_label,
                        const std::vector<ScatterSeries>& series) {
  check_size(path, kWidth, kHeight);
  cv::Mat image = canvas();
  Range xs, ys;
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) xs.add(s.x[i]), ys.add(s.y[i]);
  Panel p;
  p.area = area();
  std::tie(p.x0, p.x1) = xs.padded(true);
  std::tie(p.y0, p.y1) = ys.padded(true);
  draw_axes(image, p, title, kTargetXTicks, kTargetYTicks);
  for (size_t k = 0; k < series.size(); ++k)
    for (size_t i = 0; i < series[k].x.size(); ++i)
      if (std::isfinite(series[k].x[i]) && std::isfinite(series[k].y[i]))
        cv::circle(image, p.at(series[k].x[i], series[k].y[i]), kMarker, series_colour(k), 1, cv::LINE_AA);
  std::vector<std::string> names;
  for (const auto& s : series) names.push_back(s.name);
  legend(image, names);
  x_axis_label(image, x_label);
  save_png(path, image);
}

}  // namespace lidarloop
