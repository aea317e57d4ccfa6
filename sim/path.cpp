#include "sim/path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lidarloop {

constexpr double kCurvatureWindow = 2.0;  // m either side: smooths the polyline's 3-degree arc steps

Eigen::Isometry3d to_isometry(const Pose2d& p) {
  return Eigen::Translation3d(p.x, p.y, 0) * Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ());
}

Path make_path(Polyline2d points, bool closed) {
  Path p;
  p.points = std::move(points);
  if (closed && (p.points.front() - p.points.back()).norm() > 1e-9) p.points.push_back(p.points.front());
  p.closed = closed;
  p.arc.push_back(0);
  for (size_t i = 1; i < p.points.size(); ++i) p.arc.push_back(p.arc.back() + (p.points[i] - p.points[i - 1]).norm());
  p.length = p.arc.back();
  return p;
}

double Path::wrap(double s) const {
  if (!closed) return std::clamp(s, 0.0, length);
  s = std::fmod(s, length);
  return s < 0 ? s + length : s;
}

// Index of the segment [i, i+1] holding arc length s.
static size_t segment_at(const Path& p, double s) {
  const auto it = std::upper_bound(p.arc.begin(), p.arc.end(), s);
  const size_t i = it == p.arc.begin() ? 0 : size_t(it - p.arc.begin()) - 1;
  return std::min(i, p.points.size() - 2);
}

Pose2d Path::pose_at(double s) const {
  if (points.size() < 2) return {points.front().x(), points.front().y(), 0};
  s = wrap(s);
  size_t i = segment_at(*this, s);
  while (i + 2 < points.size() && arc[i + 1] - arc[i] < 1e-9) ++i;  // skip repeated points
  const Eigen::Vector2d d = points[i + 1] - points[i];
  const double len = arc[i + 1] - arc[i];
  const Eigen::Vector2d p = len > 0 ? Eigen::Vector2d(points[i] + d * ((s - arc[i]) / len)) : points[i];
  return {p.x(), p.y(), std::atan2(d.y(), d.x())};
}

double Path::project(const Eigen::Vector2d& q, double from, double to) const {
  if (points.size() < 2) return 0;
  double best = std::numeric_limits<double>::max(), best_s = from;
  auto scan = [&](double a, double b, double base) {  // segments overlapping [a, b] of one lap
    for (size_t i = segment_at(*this, a); i + 1 < points.size() && arc[i] <= b; ++i) {
      const Eigen::Vector2d d = points[i + 1] - points[i];
      const double len2 = d.squaredNorm();
      const double u = len2 > 0 ? std::clamp((q - points[i]).dot(d) / len2, 0.0, 1.0) : 0.0;
      const double dist = (points[i] + u * d - q).squaredNorm();
      if (dist < best) best = dist, best_s = base + arc[i] + u * std::sqrt(len2);
    }
  };
  if (!closed || to - from >= length) {
    scan(closed ? 0 : std::max(0.0, from), closed ? length : std::min(length, to), 0);
    return best_s;
  }
  // A window on a closed path may straddle the seam: scan both laps it touches, unwrapped.
  const double lap = std::floor(from / length) * length;
  scan(from - lap, std::min(length, to - lap), lap);
  if (to - lap > length) scan(0, to - lap - length, lap + length);
  return best_s;
}

// Heading interpolated linearly between segment midpoints: continuous along the path, so its
// derivative is the curvature of the arcs the polyline approximates.
static double smooth_heading(const Path& p, double s) {
  s = p.wrap(s);
  const size_t n = p.points.size() - 1;  // segments
  size_t i = std::min(n - 1, size_t(std::upper_bound(p.arc.begin(), p.arc.end(), s) - p.arc.begin()) - 1);
  auto heading = [&](size_t k) {
    const Eigen::Vector2d d = p.points[k + 1] - p.points[k];
    return std::atan2(d.y(), d.x());
  };
  auto mid = [&](size_t k) { return 0.5 * (p.arc[k] + p.arc[k + 1]); };
  const bool after = s >= mid(i);
  size_t j = after ? i + 1 : i - 1;  // the neighbouring segment on s's side of the midpoint
  if (after && i + 1 >= n) j = p.closed ? 0 : i;
  if (!after && i == 0) j = p.closed ? n - 1 : 0;
  if (j == i) return heading(i);
  double mj = mid(j);
  if (p.closed && after && j < i) mj += p.length;
  if (p.closed && !after && j > i) mj -= p.length;
  const double u = std::clamp((s - mid(i)) / (mj - mid(i)), 0.0, 1.0);
  return heading(i) + u * wrap_angle(heading(j) - heading(i));
}

double Path::curvature_at(double s) const {
  if (points.size() < 3) return 0.0;
  const double a = smooth_heading(*this, s - kCurvatureWindow), b = smooth_heading(*this, s + kCurvatureWindow);
  const double span = closed ? 2 * kCurvatureWindow : wrap(s + kCurvatureWindow) - wrap(s - kCurvatureWindow);
  return span > 0 ? wrap_angle(b - a) / span : 0.0;
}

double lane_offset(const RoadSpec& road, Lane lane, bool backward) {
  const double lane_width = road.width / road.lanes;
  const double outer = road.width / 2 - lane_width / 2;  // the lane along the curb
  double lateral = 0;
  if (road.one_way)
    lateral = lane == Lane::right ? -outer : outer;
  else
    lateral = lane == Lane::right ? -outer : -(road.lanes >= 2 ? lane_width / 2 : outer);
  if (road.lanes == 1 && !road.one_way) lateral = 0;
  return backward ? -lateral : lateral;
}

Path lane_path(const RoadSpec& road, Lane lane, bool backward, const double* offset) {
  const double lateral = offset ? *offset : lane_offset(road, lane, backward);
  Polyline2d line = offset_polyline(road.centreline, lateral, road.closed);
  if (backward) std::reverse(line.begin(), line.end());
  return make_path(std::move(line), road.closed);
}

Path crosswalk_path(const RoadSpec& road, const CrosswalkSpec& crosswalk, bool from_left) {
  const PolylineSample at = sample_polyline(road.centreline, crosswalk.at);
  const Eigen::Vector2d left(-at.tangent.y(), at.tangent.x());
  const double reach = road.width / 2 + std::min(1.5, road.sidewalk_width / 2);
  Polyline2d line = {at.point - left * reach, at.point + left * reach};
  if (from_left) std::swap(line[0], line[1]);
  return make_path(std::move(line), false);
}

}  // namespace lidarloop
