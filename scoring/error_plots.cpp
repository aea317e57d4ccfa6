#include "scoring/error_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "scoring/plot_canvas.hpp"

namespace lidarloop {

namespace {

using namespace plot;

// Look: the plot canvas's ink, and the curves' own colours.
const cv::Scalar kCurve(180, 90, 30), kTruth(120, 120, 120), kEstimate(60, 60, 60), kBackground(205, 205, 205),
    kStart(40, 160, 40), kWorst(0, 0, 200);
// The error plot's claims (BGR): the 3-sigma band a light tint of the curve's blue, the protection
// bounds vermillion (Okabe & Ito), lost stretches a warm peach (at kLostOpacity), fault events purple.
const cv::Scalar kBand(245, 228, 210), kBound(0, 94, 213), kLost(150, 200, 255), kEvent(140, 40, 140);

// Error plot layout, pixels.
constexpr int kLeftMargin = 90, kRightMargin = 30, kTopMargin = 10, kBottomMargin = 75;
constexpr int kLegendSwatch = 12, kLegendGap = 24, kEventLabelDrop = 16, kEventLabelGap = 4;
constexpr double kDash = 8;              // pixels
constexpr double kSigmaBand = 3.0;       // the band's half-width in standard deviations (99.7 % when honest)
constexpr double kBandViewPercent = 90;  // of the frames whose band and bounds are in view: value_range()
constexpr double kLostOpacity = 0.5;     // lost stretches tint what is under them
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

// One panel's data: the error, its 3-sigma half-width and (lateral, longitudinal) protection bound
// per frame, NaN where not given.
struct Series {
  std::vector<double> error, band, bound;
};

// `v` clamped to a panel's height beyond either edge of its view: the clipped drawing looks the same,
// and a bound of 1e12 m neither overflows a pixel coordinate nor takes 1e14 dashes to draw.
double in_reach(const Panel& p, double v) {
  const double span = p.y1 - p.y0;
  return std::clamp(v, p.y0 - span, p.y1 + span);
}

// A polyline drawn in dashes of kDash pixels, broken where a value is not finite.
void dashed(cv::Mat& image, const Panel& p, const std::vector<double>& t, const std::vector<double>& v,
            const cv::Scalar& colour) {
  double along = 0;  // pixels drawn since the line's start: the dash pattern runs on across frames
  for (size_t i = 1; i < t.size(); ++i) {
    if (!std::isfinite(v[i - 1]) || !std::isfinite(v[i])) continue;
    const cv::Point2d a = p.at(t[i - 1], in_reach(p, v[i - 1])), b = p.at(t[i], in_reach(p, v[i]));
    const double length = cv::norm(b - a);
    for (double d = 0; d < length; d += kDash) {
      const double to = std::min(d + kDash, length);
      if (int(std::floor((along + d) / kDash)) % 2 == 0)
        cv::line(image, a + (b - a) * (d / length), a + (b - a) * (to / length), colour, 2, cv::LINE_AA);
    }
    along += length;
  }
}

void draw_panel(cv::Mat& image, const Panel& p, const std::vector<double>& t, const Series& s,
                const std::vector<bool>& lost, const std::string& title) {
  // Drawn into the panel's own pixels, so a band or bound beyond the view is clipped at its frame.
  cv::Mat area = image(p.area);
  Panel local = p;
  local.area.x = local.area.y = 0;
  // The +-3 sigma band, a quadrilateral between each two frames that both have one.
  for (size_t i = 1; i < t.size(); ++i) {
    if (!std::isfinite(s.band[i - 1]) || !std::isfinite(s.band[i])) continue;
    const double before = in_reach(p, s.band[i - 1]), after = in_reach(p, s.band[i]);
    const cv::Point corners[] = {local.at(t[i - 1], before), local.at(t[i], after), local.at(t[i], -after),
                                 local.at(t[i - 1], -before)};
    cv::fillConvexPoly(area, corners, 4, kBand, cv::LINE_AA);
  }
  // Lost stretches over the band, tinting it: from each lost frame to the next frame (the last one a
  // frame period wide).
  for (size_t i = 0; i < t.size(); ++i) {
    if (!lost[i]) continue;
    const double to = i + 1 < t.size() ? t[i + 1] : t[i] + (i > 0 ? t[i] - t[i - 1] : 0.0);
    const cv::Rect stretch =
        cv::Rect(cv::Point(local.at(t[i], p.y1)), cv::Point(local.at(to, p.y0))) & cv::Rect(0, 0, area.cols, area.rows);
    if (stretch.empty()) continue;
    cv::Mat under = area(stretch);
    cv::addWeighted(under, 1 - kLostOpacity, cv::Mat(under.size(), under.type(), kLost), kLostOpacity, 0, under);
  }
  draw_axes(image, p, title, kTargetTimeTicks, kTargetValueTicks);
  cv::line(image, p.at(p.x0, 0), p.at(p.x1, 0), kZero, 2);
  std::vector<double> below(s.bound.size());
  std::transform(s.bound.begin(), s.bound.end(), below.begin(), [](double b) { return -b; });
  dashed(area, local, t, s.bound, kBound);
  dashed(area, local, t, below, kBound);
  // The curve, broken where a value is not finite (a diverged estimate) rather than drawn through it.
  const std::vector<double>& v = s.error;
  for (size_t i = 1; i < t.size(); ++i)
    if (std::isfinite(v[i - 1]) && std::isfinite(v[i]))
      cv::line(area, local.at(t[i - 1], v[i - 1]), local.at(t[i], v[i]), kCurve, 2, cv::LINE_AA);
  if (t.size() == 1 && std::isfinite(v[0])) cv::circle(area, local.at(t[0], v[0]), 3, kCurve, cv::FILLED, cv::LINE_AA);
}

// A panel's view: all of the error, and the band and bounds of most frames (kBandViewPercent of
// them), so that a few seconds of 5 m cold-start sigma do not flatten a 0.1 m error curve.
void value_range(const Series& s, double& lo, double& hi) {
  lo = hi = 0;  // the zero line is always in view
  std::vector<double> claims;
  for (size_t i = 0; i < s.error.size(); ++i) {
    if (std::isfinite(s.error[i])) lo = std::min(lo, s.error[i]), hi = std::max(hi, s.error[i]);
    for (double c : {s.band[i], s.bound[i]})
      if (std::isfinite(c)) claims.push_back(c);
  }
  const double claim = claims.empty() ? 0.0 : percentile_nearest_rank(claims, kBandViewPercent);
  lo = std::min(lo, -claim), hi = std::max(hi, claim);
  const double pad = std::max((hi - lo) * kValuePadFraction, kMinHalfRange);
  lo -= pad, hi += pad;
}

enum class Swatch { line, dashes, box };

// One legend entry: its swatch and its words; returns the x after it.
int legend_entry(cv::Mat& image, cv::Point at, const cv::Scalar& colour, Swatch swatch, const std::string& words) {
  const int width = kLegendSwatch * 2, mid = -kLegendSwatch / 2;
  if (swatch == Swatch::box)
    cv::rectangle(image, at + cv::Point(0, -kLegendSwatch), at + cv::Point(width, 0), colour, cv::FILLED);
  else if (swatch == Swatch::line)
    cv::line(image, at + cv::Point(0, mid), at + cv::Point(width, mid), colour, 2, cv::LINE_AA);
  else
    for (int x = 0; x < width; x += 2 * int(kDash))
      cv::line(image, at + cv::Point(x, mid), at + cv::Point(std::min(x + int(kDash), width), mid), colour, 2,
               cv::LINE_AA);
  const cv::Point words_at = at + cv::Point(kLegendSwatch * 2 + kLegendGap / 2, 0);
  text(image, words, words_at);
  return words_at.x + text_width(words) + kLegendGap;
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

void write_error_plot(const std::string& path, const std::vector<FrameError>& errors,
                      const std::vector<FaultEvent>& events, const PlotSize& size) {
  check_size(path, size.width, size.height);
  cv::Mat image(size.height, size.width, CV_8UC3, kWhite);
  std::vector<double> t;
  std::vector<bool> lost;
  Series lateral, longitudinal, heading;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (const auto& e : errors) {
    t.push_back(double(e.stamp_ns) / kNsPerS);
    lost.push_back(e.lost);
    lateral.error.push_back(e.lateral_m);
    lateral.band.push_back(kSigmaBand * e.sigma_lateral_m);
    lateral.bound.push_back(e.protection_lateral_m);
    longitudinal.error.push_back(e.longitudinal_m);
    longitudinal.band.push_back(kSigmaBand * e.sigma_longitudinal_m);
    longitudinal.bound.push_back(e.protection_longitudinal_m);
    heading.error.push_back(e.heading_rad * kDegPerRad);
    heading.band.push_back(kSigmaBand * e.sigma_heading_rad * kDegPerRad);
    heading.bound.push_back(kNaN);  // no heading protection bound
  }
  double t0 = t.empty() ? 0 : t.front(), t1 = t.empty() ? kMinTimeSpan_s : t.back();
  if (t1 - t0 < kMinTimeSpan_s) t1 = t0 + kMinTimeSpan_s;

  const int panel_step = (size.height - kTopMargin - kBottomMargin) / 3;
  const struct {
    const Series* series;
    const char* name;
    const char* unit;
  } panels[] = {
      {&lateral, "lateral error", "m"}, {&longitudinal, "longitudinal error", "m"}, {&heading, "heading error", "deg"}};
  std::vector<Panel> drawn;
  for (int k = 0; k < 3; ++k) {
    const Series& series = *panels[k].series;
    Panel p;
    p.area = cv::Rect(kLeftMargin, kTopMargin + k * panel_step + kPanelTitleHeight,
                      size.width - kLeftMargin - kRightMargin, panel_step - kPanelTitleHeight - kPanelTickLabelHeight);
    p.x0 = t0, p.x1 = t1;
    value_range(series, p.y0, p.y1);
    const std::string title = std::string(panels[k].name) + " (" + panels[k].unit + ")" +
                              (series.error.empty() ? std::string(": no scored frames")
                                                    : ", RMSE " + fixed(rmse(series.error), 3) + " " + panels[k].unit);
    draw_panel(image, p, t, series, lost, title);
    drawn.push_back(p);
  }
  // Fault events across every panel, named in the top one: right of the line, or left of it where
  // the panel ends first, each on the first row down where it clears the labels before it.
  std::vector<FaultEvent> in_time = events;
  std::stable_sort(in_time.begin(), in_time.end(),
                   [](const FaultEvent& a, const FaultEvent& b) { return a.stamp_ns < b.stamp_ns; });
  std::vector<int> row_end;  // the right end of each row's last label, pixels
  for (const FaultEvent& event : in_time) {
    const double at = double(event.stamp_ns) / kNsPerS;
    if (at < t0 || at > t1) continue;
    for (const Panel& p : drawn) cv::line(image, p.at(at, p.y0), p.at(at, p.y1), kEvent, 1, cv::LINE_AA);
    const Panel& top = drawn.front();
    const cv::Point line_top = top.at(at, top.y1);
    const int width = text_width(event.what);
    const bool fits_right = line_top.x + kEventLabelGap + width <= top.area.x + top.area.width;
    const int left = fits_right ? line_top.x + kEventLabelGap : line_top.x - kEventLabelGap - width;
    size_t row = 0;
    while (row < row_end.size() && left <= row_end[row] + kEventLabelGap) ++row;
    if (row == row_end.size()) row_end.push_back(0);
    row_end[row] = left + width;
    text(image, event.what, {left, line_top.y + kEventLabelDrop * int(row + 1)}, kTickFontScale, Align::left, kEvent);
  }
  text(image, "time (s)", {kLeftMargin + (size.width - kLeftMargin - kRightMargin) / 2, size.height - 40},
       kTitleFontScale, Align::centre);
  cv::Point legend(kLeftMargin, size.height - 12);
  legend.x = legend_entry(image, legend, kCurve, Swatch::line, "error");
  legend.x = legend_entry(image, legend, kBand, Swatch::box, "+-3 sigma (the estimate's covariance)");
  legend.x = legend_entry(image, legend, kBound, Swatch::dashes, "protection bound");
  legend.x = legend_entry(image, legend, kLost * kLostOpacity + kWhite * (1 - kLostOpacity), Swatch::box, "lost");
  legend_entry(image, legend, kEvent, Swatch::line, "fault event");
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
