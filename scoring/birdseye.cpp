#include "scoring/birdseye.hpp"

#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"

namespace lidarloop {

void write_birdseye_png(const std::string& path, const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose,
                        const std::vector<Polyline2d>& curbs, const BirdseyeOptions& o) {
  const int size = int(std::lround(2 * o.half_extent_m / o.metres_per_pixel));
  cv::Mat image(size, size, CV_8UC3, cv::Scalar(20, 20, 20));
  const Eigen::Vector2d centre = sensor_pose.translation().head<2>();
  auto pixel = [&](const Eigen::Vector2d& world) {
    const Eigen::Vector2d d = (world - centre) / o.metres_per_pixel;
    return cv::Point(int(std::lround(size / 2.0 + d.x())), int(std::lround(size / 2.0 - d.y())));
  };

  // Intensity through the Turbo colour map; 0-100 diffuse stretched over the map, retro-reflectors white.
  cv::Mat lut(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) lut.at<uint8_t>(i) = uint8_t(std::min(255, i * 255 / 60));
  cv::Mat colours;
  cv::applyColorMap(lut, colours, cv::COLORMAP_TURBO);
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d w = sensor_pose * Eigen::Vector3d(p.x, p.y, p.z);
    const cv::Point px = pixel(w.head<2>());
    if (px.x < 0 || px.y < 0 || px.x >= size || px.y >= size) continue;
    image.at<cv::Vec3b>(px) = p.intensity > 100 ? cv::Vec3b(255, 255, 255) : colours.at<cv::Vec3b>(p.intensity);
  }
  for (const auto& line : curbs)
    for (size_t i = 1; i < line.size(); ++i)
      cv::line(image, pixel(line[i - 1]), pixel(line[i]), cv::Scalar(80, 220, 80), 1, cv::LINE_AA);

  for (const auto& m : o.marks)
    for (const auto& p : m.points)
      cv::circle(image, pixel(p), 2, cv::Scalar(m.bgr[0], m.bgr[1], m.bgr[2]), -1, cv::LINE_AA);
  constexpr double kArrowLength = 4.0;  // m
  for (const auto& p : o.poses) {
    const Eigen::Vector2d from(p.pose.x, p.pose.y);
    const Eigen::Vector2d to = from + kArrowLength * Eigen::Vector2d(std::cos(p.pose.yaw), std::sin(p.pose.yaw));
    cv::arrowedLine(image, pixel(from), pixel(to), cv::Scalar(p.bgr[0], p.bgr[1], p.bgr[2]), 2, cv::LINE_AA, 0, 0.3);
  }

  // The sensor and its heading.
  const Eigen::Vector2d ahead = centre + sensor_pose.linear().col(0).head<2>().normalized() * 4.0;
  cv::arrowedLine(image, pixel(centre), pixel(ahead), cv::Scalar(255, 255, 255), 2, cv::LINE_AA, 0, 0.3);
  // Scale bar: 10 m.
  const int bar = int(std::lround(10.0 / o.metres_per_pixel));
  cv::line(image, {20, size - 20}, {20 + bar, size - 20}, cv::Scalar(255, 255, 255), 2);
  cv::putText(image, "10 m", {20, size - 28}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  const cv::Scalar white(255, 255, 255);
  const std::string title = o.title.empty() ? std::to_string(cloud.points.size()) + " points" : o.title;
  cv::putText(image, title + ", map curbs in green, north up", {20, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.5, white, 1,
              cv::LINE_AA);
  // A legend line per mark layer and pose, in its colour.
  int y = 46;
  constexpr int kLineStep = 20;
  for (const auto& m : o.marks) {
    cv::putText(image, m.label, {20, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(m.bgr[0], m.bgr[1], m.bgr[2]), 1,
                cv::LINE_AA);
    y += kLineStep;
  }
  for (const auto& p : o.poses) {
    cv::putText(image, p.label, {20, y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(p.bgr[0], p.bgr[1], p.bgr[2]), 1,
                cv::LINE_AA);
    y += kLineStep;
  }
  if (!cv::imwrite(path, image)) throw InputError(path + ": cannot write PNG");
}

}  // namespace lidarloop
