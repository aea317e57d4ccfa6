#include "mapping/survey_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {

constexpr double kMetresToCm = 100.0;
constexpr int kLaneThickness = 3;                // pixels
constexpr int kBarWidth = 240, kBarHeight = 14;  // colour bar, pixels
constexpr int kInset = 16, kTextGap = 6;         // pixels from the corner, between bar and labels
constexpr double kFontScale = 0.5;
constexpr int kTextHeight = 12;  // pixels of a line of text at kFontScale
const cv::Scalar kBackground(25, 25, 25), kCurbGrey(110, 110, 110), kText(235, 235, 235);

double position_error(const Pose2d& e) { return std::hypot(e.x, e.y); }

}  // namespace

void write_survey_error_png(const std::string& path, const World& world, const SurveyDrive& survey,
                            double min_metres_per_pixel, int max_pixels) {
  const Eigen::Vector2d lo = world.bounds.min(), size = world.bounds.sizes();
  const double mpp = std::max(min_metres_per_pixel, size.maxCoeff() / max_pixels);
  const int w = int(std::ceil(size.x() / mpp)), h = int(std::ceil(size.y() / mpp));
  cv::Mat image(h, w, CV_8UC3, kBackground);
  auto pixel = [&](const Eigen::Vector2d& p) {
    return cv::Point(int(std::lround((p.x() - lo.x()) / mpp)), int(std::lround(h - 1 - (p.y() - lo.y()) / mpp)));
  };
  for (const auto& line : world.curbs)
    for (size_t i = 1; i < line.size(); ++i) cv::line(image, pixel(line[i - 1]), pixel(line[i]), kCurbGrey, 1);

  // The colour scale runs from 0 to the largest error of the survey, rounded up to the next cm.
  double max_error = 0;
  for (const Pose2d& e : survey.error.samples) max_error = std::max(max_error, position_error(e));
  const double scale_cm = std::max(1.0, std::ceil(max_error * kMetresToCm));
  cv::Mat levels(1, 256, CV_8UC1), colours;
  for (int i = 0; i < 256; ++i) levels.at<uint8_t>(i) = uint8_t(i);
  cv::applyColorMap(levels, colours, cv::COLORMAP_TURBO);
  auto colour = [&](double error_m) {
    const int i = std::clamp(int(std::lround(error_m * kMetresToCm / scale_cm * 255)), 0, 255);
    const cv::Vec3b c = colours.at<cv::Vec3b>(i);
    return cv::Scalar(c[0], c[1], c[2]);
  };

  // Each lane in steps of about a pixel, coloured by the error where the survey car was.
  const double step = std::max(mpp, survey.error.spacing_m);
  for (const SurveyLane& lane : survey.lanes)
    for (double s = 0; s < lane.path.length; s += step) {
      const Pose2d a = lane.path.pose_at(s), b = lane.path.pose_at(std::min(s + step, lane.path.length));
      cv::line(image, pixel({a.x, a.y}), pixel({b.x, b.y}), colour(position_error(survey.error.at(lane.start_m + s))),
               kLaneThickness);
    }

  // The colour bar and its scale in the top-left corner.
  for (int x = 0; x < kBarWidth; ++x)
    cv::line(image, {kInset + x, kInset}, {kInset + x, kInset + kBarHeight},
             colour(double(x) / (kBarWidth - 1) * scale_cm / kMetresToCm));
  const int text_y = kInset + kBarHeight + kTextGap + kTextHeight;
  char right[64];
  std::snprintf(right, sizeof right, "%.0f cm", scale_cm);
  cv::putText(image, "0", {kInset, text_y}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, kText, 1, cv::LINE_AA);
  const int right_width = cv::getTextSize(right, cv::FONT_HERSHEY_SIMPLEX, kFontScale, 1, nullptr).width;
  cv::putText(image, right, {kInset + kBarWidth - right_width, text_y}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, kText, 1,
              cv::LINE_AA);
  char title[128];
  std::snprintf(title, sizeof title, "survey position error along the lanes (max %.1f cm), north up",
                max_error * kMetresToCm);
  cv::putText(image, title, {kInset + kBarWidth + 2 * kInset, kInset + kBarHeight}, cv::FONT_HERSHEY_SIMPLEX,
              kFontScale, kText, 1, cv::LINE_AA);
  if (!cv::imwrite(path, image)) throw InputError(path + ": cannot write PNG");
}

}  // namespace lidarloop
