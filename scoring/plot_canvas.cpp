#include "scoring/plot_canvas.hpp"

#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"

namespace lidarloop::plot {

namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kMinWidth = 400, kMinHeight = 300;
constexpr int kTickLabelGap = 4, kTickLabelDrop = 16, kTitleLift = 10;
}  // namespace

void text(cv::Mat& image, const std::string& s, cv::Point at, double scale, Align align, const cv::Scalar& colour) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(s, kFont, scale, 1, &baseline);
  if (align == Align::centre) at.x -= size.width / 2;
  if (align == Align::right) at.x -= size.width;
  cv::putText(image, s, at, kFont, scale, colour, 1, cv::LINE_AA);
}

int text_width(const std::string& s, double scale) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, 1, &baseline).width;
}

double nice_floor(double value) {
  const double decade = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * decade <= value) return m * decade;
  return decade;
}

double tick_step(double span, int target) {
  const double raw = span / target;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * decade >= raw) return m * decade;
  return 10 * decade;
}

std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> out;
  for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-9; v += step)
    out.push_back(std::abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

std::string tick_label(double value, double step) {
  const int decimals = std::max(0, int(std::ceil(-std::log10(step) - 1e-9)));
  return fixed(value, decimals);
}

std::string fixed(double value, int decimals) {
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", decimals, value);
  return s;
}

void draw_axes(cv::Mat& image, const Panel& p, const std::string& title, int target_x_ticks, int target_y_ticks,
               const std::vector<std::string>& x_labels) {
  auto x_tick = [&](double x, const std::string& label) {
    const cv::Point q = p.at(x, p.y0);
    cv::line(image, {q.x, p.area.y}, q, kGrid, 1);
    cv::line(image, q, {q.x, q.y + kTickLength}, kInk, 1);
    text(image, label, {q.x, q.y + kTickLength + kTickLabelDrop}, kTickFontScale, Align::centre);
  };
  if (!x_labels.empty()) {
    for (size_t k = 0; k < x_labels.size(); ++k) x_tick(double(k), x_labels[k]);
  } else {
    const double step = tick_step(p.x1 - p.x0, target_x_ticks);
    for (double t : ticks(p.x0, p.x1, step)) x_tick(t, tick_label(t, step));
  }
  const double y_step = tick_step(p.y1 - p.y0, target_y_ticks);
  for (double t : ticks(p.y0, p.y1, y_step)) {
    const cv::Point q = p.at(p.x0, t);
    cv::line(image, q, {p.area.x + p.area.width, q.y}, kGrid, 1);
    cv::line(image, {q.x - kTickLength, q.y}, q, kInk, 1);
    text(image, tick_label(t, y_step), {q.x - kTickLength - kTickLabelGap, q.y + 5}, kTickFontScale, Align::right);
  }
  cv::rectangle(image, p.area, kInk, 1);
  text(image, title, {p.area.x, p.area.y - kTitleLift}, kTitleFontScale);
}

cv::Scalar series_colour(size_t k) {
  // Okabe & Ito's palette (BGR): blue, vermillion, bluish green, orange, reddish purple, sky blue,
  // yellow, black.
  static const cv::Scalar palette[] = {{178, 114, 0},   {0, 94, 213},   {115, 158, 0},  {0, 159, 230},
                                       {167, 121, 204}, {233, 180, 86}, {66, 228, 240}, {0, 0, 0}};
  return palette[k % std::size(palette)];
}

void check_size(const std::string& path, int width, int height) {
  if (width < kMinWidth || height < kMinHeight)
    throw InputError(path + ": plot size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is too small (at least " + std::to_string(kMinWidth) + "x" + std::to_string(kMinHeight) + ")");
}

void save_png(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception&) {  // OpenCV throws for some unwritable paths, returns false for others
  }
  if (!ok) throw InputError(path + ": cannot write PNG");
}

}  // namespace lidarloop::plot
