#include "loop/error_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "loop/plot_canvas.hpp"

namespace lidarloop {

namespace {

using namespace plot;

// Look: the plot canvas's ink, and the curves' own colours.
const cv::Scalar kCurve(180, 90, 30), kTruth(120, 120, 120), kEstimate(60, 60, 60), kBackground(205, 205, 205),
    kStart(40, 160, 40), kWorst(0, 0, 200);

// Error plot layout, pixels.
constexpr int kLeftMargin = 90, kRightMargin = 30, kTopMargin = 10, kBottomMargin = 50;
constexpr int kPanelTitleHeight = 30, kPanelTickLabelHeight = 28;
constexpr int kTargetTimeTicks = 10, kTargetValueTicks = 5;
constexpr double kValuePadFraction = 0.1;  // room above and below the curve
constexpr double kMinHalfRange = 0.05;     // m or deg: an all-zero curve still gets an axis
constexpr double kMinTimeSpan_s = 1.0;

// Trajectory plot layout.
constexpr int kMapMargin = 50, kColourBarWidth = 24, kColourBarSpace = 130;
constexpr double kMapPadFraction = 0.05, kMinMapExtent_m = 10.0;
constexpr double kScaleBarFraction = 0.2;  // of the map's width, rounded down to 1-2-5
constexpr int kErrorLineThickness = 5, kMarkerRadius = 8;
constexpr double kMinColourScale_m = 0.01;
constexpr int kColourBarTicks = 5;

void draw_panel(cv::Mat& image, const Panel& p, const std::vector<double>& t, const std::vector<double>& v,
                const std::string& title) {
  draw_axes(image, p, title, kTargetTimeTicks, kTargetValueTicks);
  cv::line(image, p.at(p.x0, 0), p.at(p.x1, 0), kZero, 2);
  // The curve, broken where a value is not finite (a diverged estimate) rather than drawn through it.
  for (size_t i = 1; i < t.size(); ++i)
    if (std::isfinite(v[i - 1]) && std::isfinite(v[i]))
      cv::line(image, p.at(t[i - 1], v[i - 1]), p.at(t[i], v[i]), kCurve, 2, cv::LINE_AA);
  if (t.size() == 1 && std::isfinite(v[0])) cv::circle(image, p.at(t[0], v[0]), 3, kCurve, cv::FILLED, cv::LINE_AA);
}

// A colour for 0..1 from OpenCV's Turbo map (blue = small, red = large).
cv::Scalar turbo(double fraction) {
  static const cv::Mat colours = [] {
    cv::Mat ramp(1, 256, CV_8UC1), out;
    for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(i) = uint8_t(i);
    cv::applyColorMap(ramp, out, cv::COLORMAP_TURBO);
    return out;
  }();
  const int i = std::clamp(int(std::lround(fraction * 255)), 0, 255);
  const cv::Vec3b c = colours.at<cv::Vec3b>(i);
  return {double(c[0]), double(c[1]), double(c[2])};
}

}  // namespace

void write_error_plot(const std::string& path, const std::vector<FrameError>& errors, const PlotSize& size) {
  check_size(path, size.width, size.height);
  cv::Mat image(size.height, size.width, CV_8UC3, kWhite);
  std::vector<double> t, lateral, longitudinal, heading;
  for (const auto& e : errors) {
    t.push_back(double(e.stamp_ns) / kNsPerS);
    lateral.push_back(e.lateral_m);
    longitudinal.push_back(e.longitudinal_m);
    heading.push_back(e.heading_rad * kDegPerRad);
  }
  double t0 = t.empty() ? 0 : t.front(), t1 = t.empty() ? kMinTimeSpan_s : t.back();
  if (t1 - t0 < kMinTimeSpan_s) t1 = t0 + kMinTimeSpan_s;

  const int panel_step = (size.height - kTopMargin - kBottomMargin) / 3;
  const struct {
    const std::vector<double>* values;
    const char* name;
    const char* unit;
  } panels[] = {
      {&lateral, "lateral error", "m"}, {&longitudinal, "longitudinal error", "m"}, {&heading, "heading error", "deg"}};
  for (int k = 0; k < 3; ++k) {
    const auto& v = *panels[k].values;
    double lo = 0, hi = 0;  // the zero line is always in view
    for (double x : v)
      if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
    const double pad = std::max((hi - lo) * kValuePadFraction, kMinHalfRange);
    Panel p;
    p.area = cv::Rect(kLeftMargin, kTopMargin + k * panel_step + kPanelTitleHeight,
                      size.width - kLeftMargin - kRightMargin, panel_step - kPanelTitleHeight - kPanelTickLabelHeight);
    p.x0 = t0, p.x1 = t1, p.y0 = lo - pad, p.y1 = hi + pad;
    const std::string title =
        std::string(panels[k].name) + " (" + panels[k].unit + ")" +
        (v.empty() ? std::string(": no scored frames") : ", RMSE " + fixed(rmse(v), 3) + " " + panels[k].unit);
    draw_panel(image, p, t, v, title);
  }
  text(image, "time (s)", {kLeftMargin + (size.width - kLeftMargin - kRightMargin) / 2, size.height - 12},
       kTitleFontScale, Align::centre);
  save_png(path, image);
}

void write_trajectory_plot(const std::string& path, const std::vector<TruthPose>& truth,
                           const std::vector<EstimateRecord>& estimates, const std::vector<FrameError>& errors,
                           const std::vector<Polyline2d>& background, const PlotSize& size) {
  check_size(path, size.width, size.height);
  cv::Mat image(size.height, size.width, CV_8UC3, kWhite);

  // Frame the trajectories (not the background, which may be a whole map).
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
  auto include = [&](const Pose2d& p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  };
  for (const auto& p : truth) include(p.pose);
  for (const auto& e : estimates) include(e.pose);
  for (const auto& e : errors) include(e.truth);
  if (x0 > x1) x0 = y0 = 0, x1 = y1 = 0;  // nothing to frame: an empty plot around the origin
  const double pad = std::max(x1 - x0, y1 - y0) * kMapPadFraction;
  const double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  const double half_w = std::max((x1 - x0) / 2 + pad, kMinMapExtent_m / 2);
  const double half_h = std::max((y1 - y0) / 2 + pad, kMinMapExtent_m / 2);

  const cv::Rect area(kMapMargin, kMapMargin, size.width - 2 * kMapMargin - kColourBarSpace,
                      size.height - 2 * kMapMargin);
  const double px_per_m = std::min(area.width / (2 * half_w), area.height / (2 * half_h));  // equal aspect
  const cv::Point centre(area.x + area.width / 2, area.y + area.height / 2);
  auto pixel = [&](double x, double y) {
    return cv::Point(centre.x + int(std::lround((x - cx) * px_per_m)),
                     centre.y - int(std::lround((y - cy) * px_per_m)));
  };

  // Clip to the map area so background lines do not run over the colour bar.
  cv::Mat map = image(area);
  const cv::Point offset(-area.x, -area.y);
  for (const auto& line : background)
    for (size_t i = 1; i < line.size(); ++i)
      cv::line(map, pixel(line[i - 1].x(), line[i - 1].y()) + offset, pixel(line[i].x(), line[i].y()) + offset,
               kBackground, 1, cv::LINE_AA);
  for (size_t i = 1; i < truth.size(); ++i)
    cv::line(map, pixel(truth[i - 1].pose.x, truth[i - 1].pose.y) + offset,
             pixel(truth[i].pose.x, truth[i].pose.y) + offset, kTruth, 1, cv::LINE_AA);

  double max_error = 0;
  size_t worst = 0;
  for (size_t i = 0; i < errors.size(); ++i)
    if (std::isfinite(errors[i].position_m) && errors[i].position_m > max_error)
      max_error = errors[i].position_m, worst = i;
  // The colour scale ends at the first 1-2-5 tick at or above the largest error.
  const double colour_step = tick_step(std::max(max_error, kMinColourScale_m), kColourBarTicks);
  const double scale_max = std::max(1.0, std::ceil(max_error / colour_step - 1e-9)) * colour_step;
  // The estimate under the coloured truth: it shows where it strays from it.
  for (size_t i = 1; i < estimates.size(); ++i)
    if (std::isfinite(estimates[i - 1].pose.x + estimates[i - 1].pose.y + estimates[i].pose.x + estimates[i].pose.y))
      cv::line(map, pixel(estimates[i - 1].pose.x, estimates[i - 1].pose.y) + offset,
               pixel(estimates[i].pose.x, estimates[i].pose.y) + offset, kEstimate, 1, cv::LINE_AA);
  for (size_t i = 1; i < errors.size(); ++i) {
    const double e = errors[i].position_m;
    const cv::Scalar colour = std::isfinite(e) ? turbo(e / scale_max) : kWorst;
    cv::line(map, pixel(errors[i - 1].truth.x, errors[i - 1].truth.y) + offset,
             pixel(errors[i].truth.x, errors[i].truth.y) + offset, colour, kErrorLineThickness, cv::LINE_AA);
  }
  if (errors.size() == 1)
    cv::circle(map, pixel(errors[0].truth.x, errors[0].truth.y) + offset, kErrorLineThickness,
               turbo(errors[0].position_m / scale_max), cv::FILLED, cv::LINE_AA);
  if (!truth.empty())
    cv::circle(map, pixel(truth.front().pose.x, truth.front().pose.y) + offset, kMarkerRadius, kStart, 2, cv::LINE_AA);
  if (!errors.empty())
    cv::circle(map, pixel(errors[worst].truth.x, errors[worst].truth.y) + offset, kMarkerRadius, kWorst, 2,
               cv::LINE_AA);
  cv::rectangle(image, area, kInk, 1);

  // Scale bar, bottom left inside the map.
  const double bar_m = nice_floor(kScaleBarFraction * area.width / px_per_m);
  const int bar_px = int(std::lround(bar_m * px_per_m));
  const cv::Point bar0(area.x + 20, area.y + area.height - 20);
  cv::line(image, bar0, bar0 + cv::Point(bar_px, 0), kInk, 3);
  text(image, tick_label(bar_m, bar_m) + " m", bar0 + cv::Point(0, -10));

  // Colour bar to the right.
  const cv::Rect bar(area.x + area.width + 30, area.y + 30, kColourBarWidth, area.height - 60);
  for (int row = 0; row < bar.height; ++row)
    cv::line(image, {bar.x, bar.y + row}, {bar.x + bar.width - 1, bar.y + row},
             turbo(1.0 - double(row) / std::max(1, bar.height - 1)), 1);
  cv::rectangle(image, bar, kInk, 1);
  for (double tick : ticks(0, scale_max, colour_step)) {
    const int y = bar.y + bar.height - int(std::lround(tick / scale_max * bar.height));
    cv::line(image, {bar.x + bar.width, y}, {bar.x + bar.width + kTickLength, y}, kInk, 1);
    text(image, tick_label(tick, colour_step), {bar.x + bar.width + kTickLength + 4, y + 5});
  }
  text(image, "error (m)", {bar.x + bar.width / 2, bar.y - 20}, kTickFontScale, Align::centre);

  const std::string title = errors.empty() ? std::string("trajectory, north up: no scored frames")
                                           : "position error along the truth, north up: max " + fixed(max_error, 3) +
                                                 " m at t = " + fixed(double(errors[worst].stamp_ns) / kNsPerS, 1) +
                                                 " s (red circle)";
  text(image, title, {kMapMargin, kMapMargin - 15}, kTitleFontScale);
  text(image, "thin lines: truth (grey), estimate (dark grey); green circle: start",
       {kMapMargin, size.height - kMapMargin / 2 + 5});
  save_png(path, image);
}

}  // namespace lidarloop
