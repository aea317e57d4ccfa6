#include "sim/curb_visibility.hpp"

#include <string>

#include "sim/curb_band.hpp"

namespace lidarloop {

namespace {

bool is_cut(const std::string& kind) {
  for (CurbCut cut : {CurbCut::driveway, CurbCut::ramp, CurbCut::flush})
    if (kind == curb_cut_name(cut)) return true;
  return false;
}

}  // namespace

std::vector<Eigen::Vector3f> curb_top_samples(const std::vector<Polyline2d>& lines,
                                              const std::function<float(const Eigen::Vector2d&)>& top_height,
                                              double spacing) {
  std::vector<Eigen::Vector3f> samples;
  for (const Polyline2d& line : lines) {
    double next = 0, start = 0;  // arc length of the next sample, and of the segment's start
    for (size_t i = 0; i + 1 < line.size(); ++i) {
      const Eigen::Vector2d a = line[i], d = line[i + 1] - line[i];
      const double length = d.norm();
      for (; next < start + length; next += spacing) {
        const Eigen::Vector2d p = a + d * ((next - start) / length);
        samples.emplace_back(float(p.x()), float(p.y()), top_height(p));
      }
      start += length;
    }
  }
  return samples;
}

std::vector<Eigen::Vector3f> curb_top_samples(const World& world, double spacing) {
  std::vector<Polyline2d> raised;
  for (size_t i = 0; i < world.curbs.size(); ++i)
    if (i >= world.curb_kinds.size() || !is_cut(world.curb_kinds[i])) raised.push_back(world.curbs[i]);
  return curb_top_samples(raised, world.raised_level, spacing);
}

CurbVisibility curb_visibility(const RayScene& scene, const std::vector<Eigen::Vector3f>& samples,
                               const Eigen::Vector3f& origin, float time, const CurbVisibilityConfig& config) {
  CurbVisibility v;
  const float min2 = float(config.min_range_m * config.min_range_m);
  const float max2 = float(config.max_range_m * config.max_range_m);
  for (const Eigen::Vector3f& sample : samples) {
    const float horizontal2 = (sample.head<2>() - origin.head<2>()).squaredNorm();
    if (horizontal2 < min2 || horizontal2 > max2) continue;
    const Eigen::Vector3f to = sample - origin;
    const float distance = to.norm();
    const Ray ray{origin, to / distance, time};
    const float tfar = distance - float(config.stop_short_m);
    RayHit hit;
    if (!scene.intersect(ray, 0, tfar, hit))
      ++v.visible;
    else if (hit.actor < 0 || scene.world_occludes(ray, 0, tfar))
      ++v.blocked_by_world;
    else
      ++v.hidden;
  }
  return v;
}

}  // namespace lidarloop
