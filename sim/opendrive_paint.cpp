#include "sim/opendrive_paint.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/mesh_shapes.hpp"
#include "sim/opendrive_geometry.hpp"
#include "sim/polyline.hpp"
#include "sim/region.hpp"

namespace lidarloop {
namespace {

constexpr double kMinMark = 0.1;         // m: marks shorter than this along s are skipped
constexpr double kStripeTile = 0.25;     // m: crosswalk stripes are meshed on this grid
constexpr double kStripeOverhang = 1.0;  // m: stripes are cut from rectangles this much longer than the outline

// One painted line of a mark: its offset from the lane's edge (left positive), width and pattern.
struct MarkLine {
  double t_offset = 0, width = 0;
  double dash = 0, gap = 0;  // gap 0: solid
  double phase = 0;          // m along s before the first dash
  bool dots = false;
};

// The lines a road mark consists of, or a reason it is not painted ("" when it is painted, "-" when it
// is nothing by design: type none or curb).
std::string mark_lines(const OdrRoadMark& m, const OdrWorldParams& p, std::vector<MarkLine>& out) {
  const double w = m.width && *m.width > 0 ? *m.width : m.weight == "bold" ? p.mark_bold : p.mark_standard;
  if (m.type == "none" || m.type == "curb") return "-";
  if (!m.lines.empty()) {  // the explicit pattern replaces the type's
    for (const auto& l : m.lines) {
      const bool solid = l.length <= 0 || l.space <= 0;
      out.push_back(
          {l.t_offset, l.width > 0 ? l.width : w, solid ? 0 : l.length, solid ? 0 : l.space, l.s_offset, false});
    }
    return "";
  }
  std::istringstream words(m.type);
  std::vector<std::string> parts;
  for (std::string word; words >> word;) parts.push_back(word);
  auto line = [&](const std::string& kind, double t) -> bool {
    if (kind == "solid") return out.push_back({t, w, 0, 0, 0, false}), true;
    if (kind == "broken") return out.push_back({t, w, p.dash, p.gap, 0, false}), true;
    return false;
  };
  if (m.type == "botts dots") {
    out.push_back({0, p.botts_size, 0, p.botts_spacing, 0, true});
    return "";
  }
  if (parts.size() == 1 && line(parts[0], 0)) return "";
  // A double line: the first word is the line on the left in the direction of s (as Lanelet2's
  // solid_dashed), an assumption where the specification is silent.
  const double off = 0.5 * (w + p.double_spacing);
  if (parts.size() == 2 && line(parts[0], off) && line(parts[1], -off)) return "";
  out.clear();
  return "road mark " + m.type;
}

// The line at t_edge(s) + offset between s0 and s1, in the map's x / y.
Polyline2d edge_line(const OdrRoad& road, size_t section, int lane_id, double s0, double s1, double offset,
                     double step) {
  Polyline2d line;
  const int n = std::max(1, int(std::ceil((s1 - s0) / step)));
  for (int k = 0; k <= n; ++k) {
    const double s = s0 + (s1 - s0) * k / n;
    const OdrLaneEdges e = lane_edges(road, section, lane_id, s);
    const Eigen::Vector2d p = road_point(road, s, (lane_id == 0 ? e.inner : e.outer) + offset).head<2>();
    if (line.empty() || (p - line.back()).norm() > 1e-6) line.push_back(p);
  }
  return line;
}

void paint_lane(const OdrRoad& road, size_t section, const OdrLane& lane, const OdrWorldParams& p,
                const std::function<double(const Eigen::Vector2d&)>& ground, MaterialId paint, TriangleMesh& mesh,
                OdrBuildReport& report, MarkingPainter& painter) {
  const double sec_s = road.sections[section].s, sec_end = road.section_end(section);
  for (size_t k = 0; k < lane.marks.size(); ++k) {
    const OdrRoadMark& m = lane.marks[k];
    const double s0 = std::clamp(sec_s + m.s_offset, sec_s, sec_end);
    const double s1 = k + 1 < lane.marks.size() ? std::clamp(sec_s + lane.marks[k + 1].s_offset, s0, sec_end) : sec_end;
    if (m.type == "curb") ++report.curb_marks;
    if (s1 - s0 < kMinMark) continue;
    std::vector<MarkLine> lines;
    const std::string why = mark_lines(m, p, lines);
    if (why == "-") continue;
    if (road.junction != "-1" && !p.paint_junctions) {
      ++report.not_built["road mark on a junction's connecting road (paint_junctions is off)"];
      continue;
    }
    if (!why.empty()) {
      ++report.not_built[why];
      continue;
    }
    for (const MarkLine& l : lines) {
      const Polyline2d line = edge_line(road, section, lane.id, std::min(s1, s0 + l.phase), s1, l.t_offset, p.step);
      if (line.size() < 2) continue;
      if (l.dots) {
        const double length = polyline_length(line);
        for (double at = 0; at <= length; at += l.gap) {
          const PolylineSample q = sample_polyline(line, at);
          add_marking_quad(mesh, q.point, q.tangent, l.width / 2, l.width / 2, ground, p.geometry.paint_height, paint,
                           painter);
        }
      } else if (l.gap > 0) {
        for (const auto& piece : dashes(line, l.dash, l.gap))
          add_paint_line(mesh, piece, l.width / 2, ground, p.geometry.paint_height, paint, &painter);
      } else {
        add_paint_line(mesh, line, l.width / 2, ground, p.geometry.paint_height, paint, &painter);
      }
    }
    ++report.paint[m.type + (m.color.empty() || m.color == "standard" ? "" : " " + m.color)];
  }
}

// Stripes parallel to the road (the traffic's direction at the object), spaced across the outline.
void paint_crosswalk(const OdrRoad& road, const OdrObject& o, const OdrWorldParams& p,
                     const std::function<double(const Eigen::Vector2d&)>& ground, MaterialId paint, TriangleMesh& mesh,
                     OdrBuildReport& report, MarkingPainter& painter) {
  const Polyline2d outline = object_outline(road, o);
  if (outline.size() < 3) {
    ++report.not_built["crosswalk without an outline or a size"];
    return;
  }
  const region::Paths area = region::unite({region::to_path(outline)}, {});
  const OdrPose ref = reference_pose(road, o.s);
  const Eigen::Vector2d u(std::cos(ref.hdg), std::sin(ref.hdg)), v(-u.y(), u.x());
  double u0 = 1e18, u1 = -1e18, v0 = 1e18, v1 = -1e18;
  for (const auto& q : outline) {
    u0 = std::min(u0, q.dot(u)), u1 = std::max(u1, q.dot(u));
    v0 = std::min(v0, q.dot(v)), v1 = std::max(v1, q.dot(v));
  }
  const double period = p.crosswalk_stripe + p.crosswalk_gap;
  const int n = int(std::floor((v1 - v0 + p.crosswalk_gap) / period));
  const double start = v0 + 0.5 * ((v1 - v0) - (n * period - p.crosswalk_gap)) + p.crosswalk_stripe / 2;
  const double z = p.geometry.paint_height;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d centre = u * (0.5 * (u0 + u1)) + v * (start + k * period);
    const region::Paths stripe = region::intersect(
        region::rectangle(centre, u, 0.5 * (u1 - u0) + kStripeOverhang, p.crosswalk_stripe / 2), area);
    if (stripe.empty()) continue;
    // Each stripe its own paint (sim/paint_wear.hpp); clipped to the outline, it is meshed whole, so it
    // has no worn patches.
    bool fresh = false;
    const MaterialId look = painter.marking(paint, marking_key(centre), fresh);
    region::mesh_region(
        stripe, kStripeTile, [&](const Eigen::Vector2d& q) { return float(ground(q) + z); }, look, mesh, kStripeTile);
    ++report.crosswalk_stripes;
  }
  ++report.crosswalks;
}

}  // namespace

Polyline2d object_outline(const OdrRoad& road, const OdrObject& o) {
  const OdrPose ref = reference_pose(road, o.s);
  const Eigen::Vector2d origin = road_point(road, o.s, o.t).head<2>();
  const double h = ref.hdg + o.hdg, c = std::cos(h), s = std::sin(h);
  Polyline2d out;
  if (!o.outlines.empty()) {
    for (const auto& corner : o.outlines.front()) {
      const Eigen::Vector2d q = corner.road_frame ? Eigen::Vector2d(road_point(road, corner.u, corner.v).head<2>())
                                                  : Eigen::Vector2d(origin.x() + c * corner.u - s * corner.v,
                                                                    origin.y() + s * corner.u + c * corner.v);
      if (out.empty() || (q - out.back()).norm() > 1e-6) out.push_back(q);
    }
    return out;
  }
  if (o.length <= 0 || o.width <= 0) return out;
  for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const double lu = a * o.length / 2, lv = b * o.width / 2;
    out.emplace_back(origin.x() + c * lu - s * lv, origin.y() + s * lu + c * lv);
  }
  return out;
}

void paint_opendrive(const OdrMap& map, const OdrWorldParams& params,
                     const std::function<double(const Eigen::Vector2d&)>& ground, MaterialId lane_paint,
                     MaterialId crosswalk_paint, TriangleMesh& mesh, OdrBuildReport& report, MarkingPainter& painter) {
  for (const auto& road : map.roads) {
    for (size_t i = 0; i < road.sections.size(); ++i) {
      const OdrLaneSection& sec = road.sections[i];
      paint_lane(road, i, sec.center, params, ground, lane_paint, mesh, report, painter);
      for (const auto* side : {&sec.left, &sec.right})
        for (const auto& lane : *side) paint_lane(road, i, lane, params, ground, lane_paint, mesh, report, painter);
    }
    for (const auto& o : road.objects)
      if (o.type == "crosswalk") paint_crosswalk(road, o, params, ground, crosswalk_paint, mesh, report, painter);
  }
}

}  // namespace lidarloop
