#include "sim/opendrive_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace lidarloop {
namespace {

// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> kNodes = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                          0.9061798459386640};
constexpr std::array<double, 5> kWeights = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                            0.4786286704993665, 0.2369268850561891};
constexpr double kPanelTurn = 0.25;   // rad of heading change per quadrature panel
constexpr double kPanelLength = 5.0;  // m: at most, so poly3 arc lengths are as exact

// Integral of f over [a, b] by composite Gauss-Legendre on n panels.
template <class F>
auto integrate(const F& f, double a, double b, int n) {
  const double h = (b - a) / n;
  decltype(f(a)) sum = f(a) * 0.0;
  for (int k = 0; k < n; ++k) {
    const double mid = a + (k + 0.5) * h;
    for (size_t i = 0; i < kNodes.size(); ++i) sum += f(mid + 0.5 * h * kNodes[i]) * (0.5 * h * kWeights[i]);
  }
  return sum;
}

// poly3: u where the curve's arc length from u = 0 reaches ds.
double poly3_u(const OdrGeometry& g, double ds) {
  const auto speed = [&](double u) {
    const double dv = g.b + u * (2 * g.c + 3 * g.d * u);
    return std::sqrt(1 + dv * dv);
  };
  double u = ds;  // the arc length is never shorter than u
  for (int it = 0; it < 30; ++it) {
    const int n = std::max(1, int(std::ceil(u / kPanelLength)));
    const double f = integrate(speed, 0.0, u, n) - ds;
    const double step = f / speed(u);
    u -= step;
    if (std::abs(step) < 1e-10) break;
  }
  return std::max(0.0, u);
}

}  // namespace

double odr_piecewise(const std::vector<OdrCubic>& records, double s) {
  const OdrCubic* at = nullptr;
  for (const auto& r : records) {
    if (r.s > s + 1e-9) break;
    at = &r;
  }
  return at ? at->at(s) : 0.0;
}

Eigen::Vector2d clothoid_integral(double k0, double dk, double u) {
  if (u <= 0) return Eigen::Vector2d::Zero();
  const double turn = std::abs(k0) * u + 0.5 * std::abs(dk) * u * u;
  const int n = std::max(1, int(std::ceil(turn / kPanelTurn)));
  return integrate(
      [&](double tau) {
        const double theta = tau * (k0 + 0.5 * dk * tau);
        return Eigen::Vector2d(std::cos(theta), std::sin(theta));
      },
      0.0, u, n);
}

OdrPose geometry_pose(const OdrGeometry& g, double ds) {
  ds = std::clamp(ds, 0.0, g.length);
  const double c = std::cos(g.hdg), s = std::sin(g.hdg);
  const auto place = [&](double u, double v, double heading) {
    return OdrPose{g.x + c * u - s * v, g.y + s * u + c * v, g.hdg + heading};
  };
  switch (g.kind) {
    case OdrGeometryKind::line:
      return place(ds, 0, 0);
    case OdrGeometryKind::arc: {
      const double k = g.curvature;
      if (std::abs(k) < 1e-12) return place(ds, 0, 0);
      return place(std::sin(k * ds) / k, (1 - std::cos(k * ds)) / k, k * ds);
    }
    case OdrGeometryKind::spiral: {
      const double dk = g.length > 0 ? (g.curv_end - g.curv_start) / g.length : 0.0;
      const Eigen::Vector2d p = clothoid_integral(g.curv_start, dk, ds);
      return place(p.x(), p.y(), ds * (g.curv_start + 0.5 * dk * ds));
    }
    case OdrGeometryKind::poly3: {
      const double u = poly3_u(g, ds);
      const double v = g.a + u * (g.b + u * (g.c + u * g.d));
      const double dv = g.b + u * (2 * g.c + 3 * g.d * u);
      return place(u, v, std::atan2(dv, 1.0));
    }
    case OdrGeometryKind::param_poly3: {
      const double p = g.normalized ? (g.length > 0 ? ds / g.length : 0.0) : ds;
      const double u = g.au + p * (g.bu + p * (g.cu + p * g.du));
      const double v = g.av + p * (g.bv + p * (g.cv + p * g.dv));
      const double du = g.bu + p * (2 * g.cu + 3 * g.du * p), dv = g.bv + p * (2 * g.cv + 3 * g.dv * p);
      return place(u, v, std::atan2(dv, du));
    }
  }
  return place(ds, 0, 0);
}

OdrPose reference_pose(const OdrRoad& road, double s) {
  if (road.plan_view.empty()) return {};
  s = std::clamp(s, 0.0, road.length);
  auto it = std::upper_bound(road.plan_view.begin(), road.plan_view.end(), s,
                             [](double v, const OdrGeometry& g) { return v < g.s; });
  const OdrGeometry& g = it == road.plan_view.begin() ? road.plan_view.front() : *std::prev(it);
  return geometry_pose(g, s - g.s);
}

OdrLaneEdges lane_edges(const OdrRoad& road, size_t section, int lane_id, double s) {
  const double offset = odr_piecewise(road.lane_offset, s);
  if (lane_id == 0 || section >= road.sections.size()) return {offset, offset};
  const OdrLaneSection& sec = road.sections[section];
  const double ds = s - sec.s;
  const int side = lane_id > 0 ? 1 : -1;
  double edge = 0;  // |t| from the offset reference line
  OdrLaneEdges out{offset, offset};
  for (int id = side; std::abs(id) <= std::abs(lane_id); id += side) {
    const OdrLane* lane = sec.lane(id);
    const double inner = edge;
    if (lane && !lane->border.empty())
      edge = odr_piecewise(lane->border, ds);
    else if (lane)
      edge += std::max(0.0, odr_piecewise(lane->width, ds));
    if (id == lane_id) out = {offset + side * inner, offset + side * edge};
  }
  return out;
}

double lane_width(const OdrRoad& road, size_t section, int lane_id, double s) {
  const OdrLaneEdges e = lane_edges(road, section, lane_id, s);
  return std::abs(e.outer - e.inner);
}

double lane_height(const OdrLane& lane, double s_in_section, double across) {
  const OdrLaneHeight* at = nullptr;
  for (const auto& h : lane.height) {
    if (h.s_offset > s_in_section + 1e-9) break;
    at = &h;
  }
  if (!at) return 0;
  return at->inner + (at->outer - at->inner) * std::clamp(across, 0.0, 1.0);
}

Eigen::Vector3d road_point(const OdrRoad& road, double s, double t, double dz) {
  const OdrPose p = reference_pose(road, s);
  const double roll = odr_piecewise(road.superelevation, s);
  const double z = odr_piecewise(road.elevation, s) + t * std::tan(roll) + dz;
  return {p.x - std::sin(p.hdg) * t, p.y + std::cos(p.hdg) * t, z};
}

Eigen::Vector3d lane_surface_point(const OdrRoad& road, size_t section, const OdrLane& lane, double s, double t) {
  const OdrLaneEdges e = lane_edges(road, section, lane.id, s);
  const double width = e.outer - e.inner;
  const double across = std::abs(width) > 1e-9 ? (t - e.inner) / width : 0.0;
  const double h = lane_height(lane, s - road.sections[section].s, across);
  Eigen::Vector3d p = road_point(road, s, t, h);
  if (lane.level) p.z() = road_point(road, s, e.inner, h).z();
  return p;
}

}  // namespace lidarloop
