#include "tools/world_map_png.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {

// Colours (BGR) by material name; anything else is drawn grey.
cv::Scalar colour(const std::string& material) {
  static const std::map<std::string, cv::Scalar> table = {
      {"asphalt", {60, 60, 60}},          {"lane_paint", {255, 255, 255}}, {"crosswalk_paint", {235, 235, 235}},
      {"curb_concrete", {170, 170, 170}}, {"sidewalk", {150, 160, 175}},   {"grass", {70, 140, 70}},
      {"building", {120, 140, 190}},      {"vegetation", {40, 100, 40}},   {"vehicle_paint", {200, 80, 40}},
      {"glass", {230, 200, 150}},         {"tyre", {20, 20, 20}},          {"metal", {180, 180, 200}},
      {"retro_reflector", {0, 215, 255}}, {"traffic_cone", {0, 100, 255}}};
  const auto it = table.find(material);
  return it == table.end() ? cv::Scalar(128, 128, 128) : it->second;
}

// Curb lines by kind (the curb GeoJSON's "curb" property): curb profiles in greens and cyan, cuts in
// warm colours; anything else grey.
const std::vector<std::pair<std::string, cv::Scalar>>& curb_styles() {
  static const std::vector<std::pair<std::string, cv::Scalar>> styles = {
      {"vertical", {60, 200, 60}}, {"sloped", {150, 255, 150}}, {"rolled", {230, 220, 40}},
      {"ramp", {230, 60, 230}},    {"driveway", {0, 140, 255}}, {"flush", {40, 40, 230}}};
  return styles;
}

}  // namespace

cv::Scalar curb_colour(const std::string& kind) {
  for (const auto& [name, bgr] : curb_styles())
    if (name == kind) return bgr;
  return {128, 128, 128};
}

namespace {

// A key in the top-left corner: a stroke of each curb kind the world has, and its name.
void draw_curb_legend(cv::Mat& image, const std::vector<std::string>& kinds) {
  constexpr int kRow = 18, kMargin = 8, kStroke = 24, kWidth = 130;
  constexpr double kFontScale = 0.45;
  std::vector<std::string> present;
  for (const auto& [name, bgr] : curb_styles())
    if (std::find(kinds.begin(), kinds.end(), name) != kinds.end()) present.push_back(name);
  for (const auto& k : kinds)
    if (std::find(present.begin(), present.end(), k) == present.end()) present.push_back(k);
  if (present.empty()) return;
  const cv::Rect box(kMargin, kMargin, kWidth, kRow * int(present.size()) + kMargin);
  cv::rectangle(image, box & cv::Rect(0, 0, image.cols, image.rows), cv::Scalar(30, 30, 30), cv::FILLED);
  for (size_t i = 0; i < present.size(); ++i) {
    const int y = kMargin + kRow * int(i) + kRow / 2 + kMargin / 2;
    cv::line(image, {2 * kMargin, y}, {2 * kMargin + kStroke, y}, curb_colour(present[i]), 3);
    cv::putText(image, present[i], {3 * kMargin + kStroke, y + 5}, cv::FONT_HERSHEY_SIMPLEX, kFontScale,
                cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  }
}

}  // namespace

void write_world_map_png(const std::string& path, const World& world, const MaterialTable& materials,
                         double metres_per_pixel, const std::vector<MapOverlay>& overlays) {
  const Eigen::Vector2d size = world.bounds.sizes() / metres_per_pixel;
  if (size.maxCoeff() > 20000) throw InputError(path + ": picture would be too large; use a coarser resolution");
  cv::Mat image(int(std::ceil(size.y())), int(std::ceil(size.x())), CV_8UC3, cv::Scalar(0, 0, 0));
  auto pixel = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = (p - world.bounds.min()) / metres_per_pixel;
    return cv::Point(int(std::lround(d.x())), image.rows - 1 - int(std::lround(d.y())));
  };
  const TriangleMesh& mesh = world.mesh;
  std::vector<size_t> order(mesh.triangles.size());
  std::iota(order.begin(), order.end(), 0);
  auto top = [&](size_t i) {
    const auto& t = mesh.triangles[i];
    return std::max({mesh.vertices[t[0]].z(), mesh.vertices[t[1]].z(), mesh.vertices[t[2]].z()});
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return top(a) < top(b); });
  for (size_t i : order) {
    const auto& t = mesh.triangles[i];
    cv::Point corners[3];
    for (int k = 0; k < 3; ++k) corners[k] = pixel(mesh.vertices[t[k]].head<2>().cast<double>());
    cv::fillConvexPoly(image, corners, 3, colour(materials[mesh.materials[i]].name), cv::LINE_8);
  }
  for (size_t c = 0; c < world.curbs.size(); ++c) {
    const cv::Scalar bgr = curb_colour(c < world.curb_kinds.size() ? world.curb_kinds[c] : "");
    for (size_t i = 1; i < world.curbs[c].size(); ++i)
      cv::line(image, pixel(world.curbs[c][i - 1]), pixel(world.curbs[c][i]), bgr, 2, cv::LINE_AA);
  }
  for (const auto& o : overlays)
    for (size_t i = 1; i < o.line.size(); ++i)
      cv::line(image, pixel(o.line[i - 1]), pixel(o.line[i]), cv::Scalar(o.bgr[0], o.bgr[1], o.bgr[2]), o.thickness,
               cv::LINE_AA);
  draw_curb_legend(image, world.curb_kinds);
  if (!cv::imwrite(path, image)) throw InputError(path + ": cannot write PNG");
}

}  // namespace lidarloop
