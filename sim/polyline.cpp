#include "sim/polyline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lidarloop {

double polyline_length(const Polyline2d& line) {
  double length = 0;
  for (size_t i = 1; i < line.size(); ++i) length += (line[i] - line[i - 1]).norm();
  return length;
}

PolylineSample sample_polyline(const Polyline2d& line, double s) {
  s = std::max(0.0, s);
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d d = line[i] - line[i - 1];
    const double len = d.norm();
    if (len <= 0) continue;
    if (s <= len || i + 1 == line.size()) {
      const double u = std::min(s, len);
      return {line[i - 1] + d * (u / len), d / len};
    }
    s -= len;
  }
  return {line.back(), {1, 0}};
}

Polyline2d smooth_polyline(const Polyline2d& line, double sigma, double step) {
  const double length = polyline_length(line);
  if (line.size() < 2 || sigma <= 0 || step <= 0 || length <= 0) return line;
  const size_t n = static_cast<size_t>(std::ceil(length / step)) + 1;
  std::vector<Eigen::Vector2d> samples(n);
  for (size_t i = 0; i < n; ++i)
    samples[i] = sample_polyline(line, length * static_cast<double>(i) / static_cast<double>(n - 1)).point;
  const double spacing = length / static_cast<double>(n - 1);
  const long reach = static_cast<long>(std::ceil(3 * sigma / spacing));
  Polyline2d out(n);
  for (size_t i = 0; i < n; ++i) {
    const long here = static_cast<long>(i), last = static_cast<long>(n) - 1;
    const long half = std::min({reach, here, last - here});  // symmetric: no pull towards the inside at the ends
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double weights = 0;
    for (long j = -half; j <= half; ++j) {
      const double u = static_cast<double>(j) * spacing / sigma;
      const double w = std::exp(-0.5 * u * u);
      sum += w * samples[static_cast<size_t>(here + j)];
      weights += w;
    }
    out[i] = sum / weights;
  }
  return out;
}

double project_onto_polyline(const Polyline2d& line, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::max(), best_s = 0, s = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d d = line[i] - line[i - 1];
    const double len2 = d.squaredNorm();
    const double u = len2 > 0 ? std::clamp((p - line[i - 1]).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (line[i - 1] + u * d - p).squaredNorm();
    if (dist < best) best = dist, best_s = s + u * std::sqrt(len2);
    s += std::sqrt(len2);
  }
  return best_s;
}

static double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

Polyline2d fillet_polyline(const Polyline2d& line, double radius, bool closed, double max_step_rad) {
  const size_t n = line.size();
  if (radius <= 0 || n < 3) {
    Polyline2d out = line;
    if (closed && n > 0) out.push_back(line.front());
    return out;
  }
  Polyline2d out;
  if (!closed) out.push_back(line.front());
  const size_t first = closed ? 0 : 1, last = closed ? n : n - 1;
  for (size_t k = first; k < last; ++k) {
    const Eigen::Vector2d& p = line[k];
    const Eigen::Vector2d& prev = line[(k + n - 1) % n];
    const Eigen::Vector2d& next = line[(k + 1) % n];
    const Eigen::Vector2d a = (prev - p).normalized(), b = (next - p).normalized();
    const double turn = M_PI - std::acos(std::clamp(a.dot(b), -1.0, 1.0));  // heading change
    if (turn < 1e-6) {
      out.push_back(p);
      continue;
    }
    // Tangent length for the arc, limited to half of each adjacent segment so arcs never overlap.
    const double max_tangent = 0.5 * std::min((prev - p).norm(), (next - p).norm());
    const double r = std::min(radius, max_tangent / std::tan(turn / 2));
    const double tangent = r * std::tan(turn / 2);
    const Eigen::Vector2d start = p + a * tangent;
    const Eigen::Vector2d bisector = (a + b).normalized();
    const Eigen::Vector2d centre = p + bisector * (r / std::cos(turn / 2));
    const double sign = cross(-a, b) > 0 ? 1.0 : -1.0;  // left turn: counter-clockwise arc
    const int steps = std::max(1, static_cast<int>(std::ceil(turn / max_step_rad)));
    const Eigen::Vector2d r0 = start - centre;
    for (int i = 0; i <= steps; ++i) {
      const double angle = sign * turn * i / steps;
      out.push_back(centre + Eigen::Rotation2D<double>(angle) * r0);
    }
  }
  if (closed)
    out.push_back(out.front());
  else
    out.push_back(line.back());
  return out;
}

Polyline2d offset_polyline(const Polyline2d& line, double offset, bool closed) {
  const size_t n = line.size();
  Polyline2d out;
  auto normal = [&](size_t i) {  // left normal of segment i -> i+1
    const Eigen::Vector2d d = (line[i + 1] - line[i]).normalized();
    return Eigen::Vector2d(-d.y(), d.x());
  };
  // Mitred join: the averaged normal, lengthened so both offset segments stay at `offset`.
  auto mitre = [](const Eigen::Vector2d& n0, const Eigen::Vector2d& n1) {
    return Eigen::Vector2d((n0 + n1).normalized() / std::max(0.2, std::sqrt(0.5 * (1 + n0.dot(n1)))));
  };
  for (size_t i = 0; i < n; ++i) {
    const bool interior = i > 0 && i + 1 < n;
    Eigen::Vector2d nrm;
    if (interior)
      nrm = mitre(normal(i - 1), normal(i));
    else if (closed)
      nrm = mitre(normal(n - 2), normal(0));  // first point == last point
    else
      nrm = normal(i == 0 ? 0 : n - 2);
    out.push_back(line[i] + offset * nrm);
  }
  return out;
}

bool segments_intersect(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
                        const Eigen::Vector2d& b1) {
  const double d1 = cross(a1 - a0, b0 - a0), d2 = cross(a1 - a0, b1 - a0);
  const double d3 = cross(b1 - b0, a0 - b0), d4 = cross(b1 - b0, a1 - b0);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  // Touching or overlapping: an end point of one segment lies on the other.
  auto on = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q0, const Eigen::Vector2d& q1, double c) {
    return c == 0 && p.x() >= std::min(q0.x(), q1.x()) && p.x() <= std::max(q0.x(), q1.x()) &&
           p.y() >= std::min(q0.y(), q1.y()) && p.y() <= std::max(q0.y(), q1.y());
  };
  return on(b0, a0, a1, d1) || on(b1, a0, a1, d2) || on(a0, b0, b1, d3) || on(a1, b0, b1, d4);
}

std::optional<std::pair<size_t, size_t>> find_self_intersection(const Polyline2d& line, bool closed) {
  const size_t segments = line.size() - 1;
  for (size_t i = 0; i < segments; ++i)
    for (size_t j = i + 2; j < segments; ++j) {
      if (closed && i == 0 && j + 1 == segments) continue;  // first and last segments share a point
      if (segments_intersect(line[i], line[i + 1], line[j], line[j + 1])) return std::make_pair(i, j);
    }
  return std::nullopt;
}

}  // namespace lidarloop
