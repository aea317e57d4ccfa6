#include "sim/region.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace lidarloop::region {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;

namespace {

constexpr double kArcTolerance = 0.005 * kScale;  // round joins deviate at most 5 mm from a true arc

IntPoint to_int(const Eigen::Vector2d& p) {
  return {static_cast<cInt>(std::llround(p.x() * kScale)), static_cast<cInt>(std::llround(p.y() * kScale))};
}
Eigen::Vector2d to_metres(const IntPoint& p) { return {double(p.X) / kScale, double(p.Y) / kScale}; }

Paths boolean(const Paths& a, const Paths& b, ClipperLib::ClipType type) {
  ClipperLib::Clipper c;
  c.AddPaths(a, ClipperLib::ptSubject, true);
  c.AddPaths(b, ClipperLib::ptClip, true);
  Paths out;
  c.Execute(type, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

int64_t cross(const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  return (b.X - a.X) * (c.Y - a.Y) - (b.Y - a.Y) * (c.X - a.X);
}

Paths square(cInt x0, cInt y0, cInt size) {
  return {{{x0, y0}, {x0 + size, y0}, {x0 + size, y0 + size}, {x0, y0 + size}}};
}

// Where a square stands against a region (nonzero winding, as Clipper fills it).
enum class Placement { inside, outside, crossed };

// An axis-aligned square, in Clipper's integer units.
struct Square {
  cInt x0, y0, size;
};

// Inside or outside only when no edge of the region comes within the closed square's bounding box,
// except edges on the sides of `clipped_to`, the square the region was cut to, which the square lies in:
// they cannot enter it. The square then lies in one face of the region, whose winding number its centre
// gives exactly (integer coordinates). Anything nearer is `crossed`, for Clipper to cut.
Placement place_square(const Paths& region, const std::optional<Square>& clipped_to, const Square& q) {
  if (q.size < 2) return Placement::crossed;  // no centre off its sides
  const cInt x1 = q.x0 + q.size, y1 = q.y0 + q.size;
  auto on_side = [&](const IntPoint& a, const IntPoint& b) {
    if (!clipped_to) return false;
    const Square& c = *clipped_to;
    return (a.X == b.X && (a.X == c.x0 || a.X == c.x0 + c.size)) ||
           (a.Y == b.Y && (a.Y == c.y0 || a.Y == c.y0 + c.size));
  };
  const IntPoint centre{q.x0 + q.size / 2, q.y0 + q.size / 2};
  int winding = 0;
  for (const Path& path : region)
    for (size_t i = 0; i < path.size(); ++i) {
      const IntPoint &a = path[i], &b = path[(i + 1) % path.size()];
      if (std::max(a.X, b.X) >= q.x0 && std::min(a.X, b.X) <= x1 && std::max(a.Y, b.Y) >= q.y0 &&
          std::min(a.Y, b.Y) <= y1 && !on_side(a, b))
        return Placement::crossed;
      if (a.Y <= centre.Y) {
        if (b.Y > centre.Y && cross(a, b, centre) > 0) ++winding;
      } else if (b.Y <= centre.Y && cross(a, b, centre) < 0) {
        --winding;
      }
    }
  return winding != 0 ? Placement::inside : Placement::outside;
}

struct IntPointHash {
  size_t operator()(const IntPoint& p) const { return std::hash<uint64_t>()(uint64_t(p.X) * 1000003u + uint64_t(p.Y)); }
};

struct Mesher {
  const std::function<float(const Eigen::Vector2d&)>& height;
  MaterialId material;
  TriangleMesh& mesh;
  cInt leaf_size, min_size, max_square;
  // Each inner corner of the grid is a corner of four squares: its height (a sum of sinusoids and a
  // nearest-road search) is worked out once. The same point gives the same bits either way.
  std::unordered_map<IntPoint, float, IntPointHash> heights{};

  float height_at(const IntPoint& p) {
    const auto [it, added] = heights.try_emplace(p, 0.0f);
    if (added) it->second = height(to_metres(p));
    return it->second;
  }

  void emit(const Path& polygon) {
    const auto base = static_cast<uint32_t>(mesh.vertices.size());
    for (const auto& p : polygon) {
      const Eigen::Vector2d xy = to_metres(p);
      mesh.vertices.emplace_back(float(xy.x()), float(xy.y()), height_at(p));
    }
    for (const auto& t : triangulate_polygon(polygon))
      mesh.add_triangle(base + t[0], base + t[1], base + t[2], material);
  }

  void fill(cInt x0, cInt y0, cInt size) {
    const cInt step = std::min(size, max_square);
    for (cInt y = y0; y < y0 + size; y += step)
      for (cInt x = x0; x < x0 + size; x += step) emit(square(x, y, step)[0]);
  }

  // `parent` is the region cut to `clipped_to` (the root's is the whole region).
  void node(const Paths& parent, const std::optional<Square>& clipped_to, cInt x0, cInt y0, cInt size) {
    // Most squares lie wholly in or out of the region, and clipping them is most of the meshing's time.
    switch (place_square(parent, clipped_to, {x0, y0, size})) {
      case Placement::outside:
        return;
      case Placement::inside:
        return fill(x0, y0, size);
      case Placement::crossed:
        break;
    }
    const Paths piece = intersect(parent, square(x0, y0, size));
    if (piece.empty()) return;
    double covered = 0;
    bool has_hole = false;
    for (const auto& p : piece) {
      covered += ClipperLib::Area(p);
      has_hole = has_hole || !ClipperLib::Orientation(p);
    }
    if (covered >= double(size) * double(size) * (1 - 1e-9)) return fill(x0, y0, size);
    if (size > leaf_size || (has_hole && size > min_size)) {
      const cInt h = size / 2;
      for (int k = 0; k < 4; ++k) node(piece, Square{x0, y0, size}, x0 + (k & 1) * h, y0 + (k >> 1) * h, h);
      return;
    }
    for (auto p : piece) {
      if (!ClipperLib::Orientation(p)) continue;  // a hole smaller than min_size: not worth meshing
      ClipperLib::CleanPolygon(p, 2.0);
      if (p.size() >= 3) emit(p);
    }
  }
};

}  // namespace

Path to_path(const Polyline2d& line) {
  Path path;
  for (const auto& p : line) path.push_back(to_int(p));
  return path;
}

Polyline2d to_polyline(const Path& path, bool repeat_first) {
  Polyline2d line;
  for (const auto& p : path) line.push_back(to_metres(p));
  if (repeat_first && !path.empty()) line.push_back(to_metres(path.front()));
  return line;
}

Paths strip(const Polyline2d& centreline, double half_width, bool closed_line) {
  ClipperLib::ClipperOffset off(2.0, kArcTolerance);
  Path path = to_path(centreline);
  if (closed_line && path.size() > 1 && path.front() == path.back()) path.pop_back();
  off.AddPath(path, ClipperLib::jtRound, closed_line ? ClipperLib::etClosedLine : ClipperLib::etOpenButt);
  Paths out;
  off.Execute(out, half_width * kScale);
  return out;
}

Paths rectangle(const Eigen::Vector2d& centre, const Eigen::Vector2d& axis, double half_length, double half_width) {
  const Eigen::Vector2d u = axis.normalized(), v(-u.y(), u.x());
  return {{to_int(centre - u * half_length - v * half_width), to_int(centre + u * half_length - v * half_width),
           to_int(centre + u * half_length + v * half_width), to_int(centre - u * half_length + v * half_width)}};
}

Paths offset(const Paths& region, double delta) {
  ClipperLib::ClipperOffset off(2.0, kArcTolerance);
  off.AddPaths(region, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  Paths out;
  off.Execute(out, delta * kScale);
  return out;
}

Paths unite(const Paths& a, const Paths& b) { return boolean(a, b, ClipperLib::ctUnion); }
Paths subtract(const Paths& a, const Paths& b) { return boolean(a, b, ClipperLib::ctDifference); }
Paths intersect(const Paths& a, const Paths& b) { return boolean(a, b, ClipperLib::ctIntersection); }

Paths closing(const Paths& region, double radius) {
  if (radius <= 0) return unite(region, {});
  // Offsetting back loses a few millimetres at convex corners; the union keeps the original whole.
  return unite(region, offset(offset(region, radius), -radius));
}

std::vector<Polyline2d> clip_lines_outside(const std::vector<Polyline2d>& lines, const Paths& region) {
  // Clipper's difference with no clip paths returns no open paths at all, not the subject.
  if (region.empty()) {
    std::vector<Polyline2d> out;
    for (const auto& line : lines) out.push_back(to_polyline(to_path(line), false));
    return out;
  }
  ClipperLib::Clipper c;
  for (const auto& line : lines) c.AddPath(to_path(line), ClipperLib::ptSubject, false);
  c.AddPaths(region, ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  c.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  Paths open;
  ClipperLib::OpenPathsFromPolyTree(tree, open);
  std::vector<Polyline2d> out;
  for (const auto& p : open) out.push_back(to_polyline(p, false));
  return out;
}

bool contains(const Paths& region, const Eigen::Vector2d& p) {
  const IntPoint q = to_int(p);
  int winding = 0;
  for (const auto& path : region)
    if (ClipperLib::PointInPolygon(q, path) != 0) winding += ClipperLib::Orientation(path) ? 1 : -1;
  return winding > 0;
}

ContainsIndex::ContainsIndex(const Paths& region, double band_m)
    : band_(std::max<cInt>(1, std::llround(band_m * kScale))) {
  cInt min_y = INT64_MAX, max_y = INT64_MIN;
  for (const auto& path : region)
    for (const auto& p : path) min_y = std::min(min_y, p.Y), max_y = std::max(max_y, p.Y);
  if (min_y > max_y) return;
  y0_ = min_y;
  bands_.resize(size_t((max_y - min_y) / band_) + 1);
  for (size_t k = 0; k < region.size(); ++k) {
    const Path& path = region[k];
    path_sign_.push_back(ClipperLib::Orientation(path) ? 1 : -1);
    if (path.size() < 3) continue;  // PointInPolygon's answer for it is always 0
    for (size_t i = 0; i < path.size(); ++i) {
      const IntPoint& a = path[i];
      const IntPoint& b = path[(i + 1) % path.size()];
      const cInt lo = std::min(a.Y, b.Y), hi = std::max(a.Y, b.Y);
      for (cInt band = (lo - y0_) / band_; band <= (hi - y0_) / band_; ++band)
        bands_[size_t(band)].push_back({a, b, int(k)});
    }
  }
}

bool ContainsIndex::contains(const Eigen::Vector2d& p) const {
  const IntPoint q = to_int(p);
  if (bands_.empty() || q.Y < y0_ || (q.Y - y0_) / band_ >= cInt(bands_.size())) return false;
  const std::vector<Edge>& edges = bands_[size_t((q.Y - y0_) / band_)];
  int winding = 0;
  // ClipperLib::PointInPolygon's loop over one path's edges (in the band), with its -1 (on the
  // boundary) folded into "inside", as contains() takes any non-zero answer.
  for (size_t i = 0; i < edges.size();) {
    const int path = edges[i].path;
    bool inside = false, on_boundary = false;
    for (; i < edges.size() && edges[i].path == path; ++i) {
      if (on_boundary) continue;
      const IntPoint &ip = edges[i].a, &next = edges[i].b;
      if (next.Y == q.Y && (next.X == q.X || (ip.Y == q.Y && ((next.X > q.X) == (ip.X < q.X))))) {
        on_boundary = true;
        continue;
      }
      if ((ip.Y < q.Y) == (next.Y < q.Y)) continue;
      if (ip.X >= q.X && next.X > q.X) {
        inside = !inside;
      } else if (ip.X >= q.X || next.X > q.X) {
        const double d = double(ip.X - q.X) * double(next.Y - q.Y) - double(next.X - q.X) * double(ip.Y - q.Y);
        if (d == 0)
          on_boundary = true;
        else if ((d > 0) == (next.Y > ip.Y))
          inside = !inside;
      }
    }
    if (inside || on_boundary) winding += path_sign_[size_t(path)];
  }
  return winding > 0;
}

double area(const Paths& region) {
  double a = 0;
  for (const auto& p : region) a += ClipperLib::Area(p);
  return a / (kScale * kScale);
}

void mesh_region(const Paths& region, double tile_size, const std::function<float(const Eigen::Vector2d&)>& height,
                 MaterialId material, TriangleMesh& mesh, double max_square) {
  if (region.empty()) return;
  const auto leaf = static_cast<cInt>(std::llround(tile_size * kScale));
  cInt min_x = INT64_MAX, min_y = INT64_MAX, max_x = INT64_MIN, max_y = INT64_MIN;
  for (const auto& path : region)
    for (const auto& p : path) {
      min_x = std::min(min_x, p.X), min_y = std::min(min_y, p.Y);
      max_x = std::max(max_x, p.X), max_y = std::max(max_y, p.Y);
    }
  // Root square: a power-of-two multiple of the tile, on the global tile grid, covering the region.
  auto floor_to = [](cInt v, cInt step) { return (v >= 0 ? v / step : (v - step + 1) / step) * step; };
  const cInt x0 = floor_to(min_x, leaf), y0 = floor_to(min_y, leaf);
  cInt size = leaf;
  while (x0 + size < max_x || y0 + size < max_y) size *= 2;
  // Full squares are split into leaves of the same power-of-two grid, so they still meet their neighbours.
  const double max_full = std::min(max_square * kScale, 4e18);
  cInt full = leaf;
  while (double(full) * 2 <= max_full && full < size) full *= 2;
  while (double(full) > max_full && full > 1) full /= 2;
  Mesher mesher{height, material, mesh, leaf, std::max<cInt>(leaf / 16, 1), full};
  mesher.node(region, std::nullopt, x0, y0, size);
}

std::vector<std::array<uint32_t, 3>> triangulate_polygon(const Path& polygon) {
  std::vector<std::array<uint32_t, 3>> out;
  std::vector<uint32_t> idx(polygon.size());
  for (uint32_t i = 0; i < idx.size(); ++i) idx[i] = i;
  if (!ClipperLib::Orientation(polygon)) std::reverse(idx.begin(), idx.end());

  auto inside = [&](const IntPoint& p, const IntPoint& a, const IntPoint& b, const IntPoint& c) {
    return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
  };
  while (idx.size() > 3) {
    const size_t m = idx.size();
    bool clipped = false;
    for (size_t i = 0; i < m && !clipped; ++i) {
      const uint32_t ia = idx[(i + m - 1) % m], ib = idx[i], ic = idx[(i + 1) % m];
      const IntPoint &a = polygon[ia], &b = polygon[ib], &c = polygon[ic];
      const int64_t turn = cross(a, b, c);
      if (turn == 0) {  // collinear vertex: drop it, no triangle
        idx.erase(idx.begin() + long(i));
        clipped = true;
        break;
      }
      if (turn < 0) continue;  // reflex
      bool ear = true;
      for (size_t j = 0; j < m && ear; ++j) {
        const IntPoint& p = polygon[idx[j]];
        if (idx[j] == ia || idx[j] == ib || idx[j] == ic || p == a || p == b || p == c) continue;
        ear = !inside(p, a, b, c);
      }
      if (!ear) continue;
      out.push_back({ia, ib, ic});
      idx.erase(idx.begin() + long(i));
      clipped = true;
    }
    if (!clipped) {
      // Only possible for numerically degenerate input: take the first convex corner regardless.
      for (size_t i = 0; i < m && !clipped; ++i) {
        const uint32_t ia = idx[(i + m - 1) % m], ib = idx[i], ic = idx[(i + 1) % m];
        if (cross(polygon[ia], polygon[ib], polygon[ic]) > 0) {
          out.push_back({ia, ib, ic});
          idx.erase(idx.begin() + long(i));
          clipped = true;
        }
      }
      if (!clipped) return out;
    }
  }
  if (idx.size() == 3 && cross(polygon[idx[0]], polygon[idx[1]], polygon[idx[2]]) > 0)
    out.push_back({idx[0], idx[1], idx[2]});
  return out;
}

}  // namespace lidarloop::region
