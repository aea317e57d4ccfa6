#pragma once
// What every PNG plot of the project draws with: black ink on white, one font, 1-2-5 ticks, axes with
// a grid, written as PNG with a clear error. loop/error_plots and loop/sweep_plots are built on it.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace lidarloop::plot {

const cv::Scalar kWhite(255, 255, 255), kInk(30, 30, 30), kGrid(225, 225, 225), kZero(150, 150, 150);
constexpr double kTickFontScale = 0.5, kTitleFontScale = 0.65;
constexpr int kTickLength = 5;

enum class Align { left, centre, right };

// Text with its baseline at `at`, aligned horizontally about at.x.
void text(cv::Mat& image, const std::string& s, cv::Point at, double scale = kTickFontScale, Align align = Align::left,
          const cv::Scalar& colour = kInk);
// The width of `s` in pixels as text() draws it.
int text_width(const std::string& s, double scale = kTickFontScale);

double nice_floor(double value);            // 1, 2 or 5 times a power of ten, the largest <= value
double tick_step(double span, int target);  // a 1-2-5 step giving about `target` ticks
std::vector<double> ticks(double lo, double hi, double step);
std::string tick_label(double value, double step);  // enough decimals to tell neighbouring ticks apart
std::string fixed(double value, int decimals);

// A plotting area and the data ranges mapped onto it.
struct Panel {
  cv::Rect area;
  double x0, x1, y0, y1;
  cv::Point at(double x, double y) const {
    return {area.x + int(std::lround((x - x0) / (x1 - x0) * area.width)),
            area.y + area.height - int(std::lround((y - y0) / (y1 - y0) * area.height))};
  }
};

// Grid, ticks and tick labels (about the target counts), the frame and a title above it.
// `x_labels`: words for the x ticks at 0, 1, 2, ... instead of numbers (categories).
void draw_axes(cv::Mat& image, const Panel& p, const std::string& title, int target_x_ticks, int target_y_ticks,
               const std::vector<std::string>& x_labels = {});

// A distinct colour for series k (a colour-blind-safe palette, Okabe & Ito 2008).
cv::Scalar series_colour(size_t k);

// Throws InputError naming `path` unless the plot is at least 400 x 300 pixels.
void check_size(const std::string& path, int width, int height);
// Writes the image; InputError naming `path` when it cannot.
void save_png(const std::string& path, const cv::Mat& image);

}  // namespace lidarloop::plot
