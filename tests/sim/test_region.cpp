// Planar region helpers on Clipper: triangulation, meshing, closing, strips, line clipping.
// Known truth: shoelace areas of hand-made polygons and closed-form areas of fillets and strips.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "sim/polyline.hpp"
#include "sim/region.hpp"

namespace lidarloop {
namespace {

using ClipperLib::IntPoint;
using ClipperLib::Path;

constexpr double kFilletFraction = 1.0 - std::numbers::pi / 4.0;  // fillet area / r^2 at a right-angle corner

// Clipper path from metres.
Path path_m(std::initializer_list<std::array<double, 2>> points) {
  Polyline2d line;
  for (const auto& p : points) line.emplace_back(p[0], p[1]);
  return region::to_path(line);
}

// Twice the signed area of a triangle (Clipper integer units).
double cross2(const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  return double(b.X - a.X) * double(c.Y - a.Y) - double(b.Y - a.Y) * double(c.X - a.X);
}

// Shoelace area in m^2 (positive for counter-clockwise).
double shoelace_m2(const Path& p) {
  double twice = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const IntPoint &a = p[i], &b = p[(i + 1) % p.size()];
    twice += double(a.X) * double(b.Y) - double(b.X) * double(a.Y);
  }
  return 0.5 * twice / (region::kScale * region::kScale);
}

// Triangulates and checks: every triangle counter-clockwise (strictly), areas add up to the polygon's.
void expect_exact_triangulation(const Path& polygon, const char* what) {
  const auto triangles = region::triangulate_polygon(polygon);
  double total = 0;
  for (const auto& t : triangles) {
    for (uint32_t i : t) ASSERT_LT(i, polygon.size()) << what;
    const double twice = cross2(polygon[t[0]], polygon[t[1]], polygon[t[2]]);
    EXPECT_GT(twice, 0) << what << ": triangle " << t[0] << "," << t[1] << "," << t[2] << " is not counter-clockwise";
    total += 0.5 * twice / (region::kScale * region::kScale);
  }
  // Integer coordinates: the sum is exact up to floating-point rounding.
  EXPECT_NEAR(total, std::abs(shoelace_m2(polygon)), 1e-9) << what;
}

// Area of a mesh's triangles projected on the ground plane.
double mesh_area(const TriangleMesh& mesh) {
  double total = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    total +=
        0.5 * ((double(b.x()) - a.x()) * (double(c.y()) - a.y()) - (double(b.y()) - a.y()) * (double(c.x()) - a.x()));
  }
  return total;
}

// A regular polygon approximating a circle, counter-clockwise.
Path circle(const Eigen::Vector2d& centre, double radius, int sides) {
  Polyline2d line;
  for (int i = 0; i < sides; ++i) {
    const double a = 2 * std::numbers::pi * i / sides;
    line.push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return region::to_path(line);
}

// ---------------------------------------------------------------------------------------------- triangulation

TEST(RegionTriangulate, ConvexPolygon) {
  const Path hexagon = circle({3, -2}, 5, 6);
  expect_exact_triangulation(hexagon, "hexagon");
  EXPECT_EQ(region::triangulate_polygon(hexagon).size(), hexagon.size() - 2);  // n - 2 for a simple polygon
}

TEST(RegionTriangulate, ConcaveLShape) {
  // The reflex corner at (2, 2) is where naive fan triangulation would go outside.
  const Path l_shape = path_m({{0, 0}, {10, 0}, {10, 2}, {2, 2}, {2, 10}, {0, 10}});
  expect_exact_triangulation(l_shape, "L-shape");
  EXPECT_EQ(region::triangulate_polygon(l_shape).size(), l_shape.size() - 2);
  EXPECT_NEAR(shoelace_m2(l_shape), 36.0, 1e-9);  // 10x2 + 2x8
}

TEST(RegionTriangulate, ClockwiseInputStillGivesCounterClockwiseTriangles) {
  Path l_shape = path_m({{0, 0}, {10, 0}, {10, 2}, {2, 2}, {2, 10}, {0, 10}});
  std::reverse(l_shape.begin(), l_shape.end());
  ASSERT_LT(shoelace_m2(l_shape), 0);
  expect_exact_triangulation(l_shape, "clockwise L-shape");
}

TEST(RegionTriangulate, CollinearPoints) {
  // Points in the middle of edges (as tile clipping produces): no zero-area triangles, same area.
  const Path square = path_m({{0, 0}, {5, 0}, {10, 0}, {10, 5}, {10, 10}, {5, 10}, {0, 10}, {0, 5}});
  expect_exact_triangulation(square, "square with mid-edge points");
  const Path comb = path_m({{0, 0},
                            {4, 0},
                            {8, 0},
                            {12, 0},
                            {12, 3},
                            {9, 3},
                            {9, 1},
                            {7, 1},
                            {7, 3},
                            {3, 3},
                            {3, 1},
                            {1, 1},
                            {1, 3},
                            {0, 3},
                            {0, 1.5}});
  expect_exact_triangulation(comb, "comb with collinear points");
}

// ---------------------------------------------------------------------------------------------- meshing

TEST(RegionMesh, SquareWithCircularHole) {
  constexpr double kHalf = 30.0, kHoleRadius = 11.0, kTile = 8.0;
  constexpr float kHeight = 0.15f;
  const region::Paths square = region::rectangle({2.5, -1.5}, {1, 0}, kHalf, kHalf);
  const region::Paths hole{circle({4, 0}, kHoleRadius, 90)};
  const region::Paths ring = region::subtract(square, hole);
  ASSERT_NEAR(region::area(ring), 4 * kHalf * kHalf - std::abs(shoelace_m2(hole[0])), 1e-6);

  TriangleMesh mesh;
  constexpr MaterialId kMaterial = 7;
  region::mesh_region(
      ring, kTile, [](const Eigen::Vector2d&) { return kHeight; }, kMaterial, mesh);
  ASSERT_GT(mesh.triangle_count(), 0u);
  EXPECT_NEAR(mesh_area(mesh), region::area(ring), 1e-3 * region::area(ring));
  for (size_t i = 0; i < mesh.triangle_count(); ++i) {
    const auto& t = mesh.triangles[i];
    EXPECT_EQ(mesh.materials[i], kMaterial);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (uint32_t v : t) {
      EXPECT_EQ(mesh.vertices[v].z(), kHeight);
      centroid += mesh.vertices[v].cast<double>() / 3;
    }
    // Every triangle faces up (counter-clockwise from above) and lies in the region, not in the hole.
    const Eigen::Vector3f n =
        (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    EXPECT_GT(n.z(), 0) << "triangle " << i;
    EXPECT_TRUE(region::contains(ring, centroid.head<2>())) << "triangle " << i << " centroid " << centroid.transpose();
  }
}

TEST(RegionMesh, TilesFollowTheGlobalGrid) {
  // A square not aligned with the tile grid: every vertex is on a grid line (a multiple of the tile)
  // or on the region's edge, so neighbouring regions meshed separately share tile edges; triangles
  // touching the edge are at most one tile (inside, whole covered squares may be larger).
  constexpr double kTile = 8.0, kHalf = 20.0;
  TriangleMesh mesh;
  region::mesh_region(
      region::rectangle({0, 0}, {1, 0}, kHalf, kHalf), kTile, [](const Eigen::Vector2d&) { return 0.0f; }, 0, mesh);
  EXPECT_NEAR(mesh_area(mesh), 4 * kHalf * kHalf, 1e-3);
  auto on_grid_or_edge = [&](float v) {
    return std::abs(std::abs(v) - kHalf) < 1e-4 || std::abs(v / kTile - std::round(v / kTile)) < 1e-6;
  };
  for (const auto& v : mesh.vertices) EXPECT_TRUE(on_grid_or_edge(v.x()) && on_grid_or_edge(v.y())) << v.transpose();
  for (const auto& t : mesh.triangles) {
    bool touches_edge = false;
    for (uint32_t i : t) touches_edge = touches_edge || mesh.vertices[i].head<2>().cwiseAbs().maxCoeff() > kHalf - 1e-4;
    if (!touches_edge) continue;
    for (int k = 0; k < 3; ++k)
      EXPECT_LE((mesh.vertices[t[k]] - mesh.vertices[t[(k + 1) % 3]]).norm(), kTile * std::sqrt(2.0) + 1e-3);
  }
}

// ---------------------------------------------------------------------------------------------- regions

TEST(RegionStrip, StraightCentrelineArea) {
  constexpr double kLength = 50.0, kWidth = 7.0;
  const region::Paths s = region::strip({{0, 0}, {30, 40}}, kWidth / 2, false);  // a 3-4-5 diagonal, 50 m
  EXPECT_NEAR(region::area(s), kLength * kWidth, 1e-3);
  EXPECT_TRUE(region::contains(s, {15, 20}));
  EXPECT_FALSE(region::contains(s, {-1, -1}));  // butt ends: nothing beyond the end points
  EXPECT_FALSE(region::contains(s, {31, 41.5}));
}

TEST(RegionStrip, ClosedCentrelineIsARing) {
  // A closed 100 m square centreline: the ring has sharp inner corners and round outer ones,
  // area = outer (A + P h + pi h^2) - inner ((side - 2h)^2).
  constexpr double kSide = 100.0, kHalfWidth = 5.0;
  const region::Paths ring = region::strip({{0, 0}, {kSide, 0}, {kSide, kSide}, {0, kSide}, {0, 0}}, kHalfWidth, true);
  const double outer = kSide * kSide + 4 * kSide * kHalfWidth + std::numbers::pi * kHalfWidth * kHalfWidth;
  const double inner = (kSide - 2 * kHalfWidth) * (kSide - 2 * kHalfWidth);
  EXPECT_NEAR(region::area(ring), outer - inner, 1e-3 * (outer - inner));
  EXPECT_FALSE(region::contains(ring, {kSide / 2, kSide / 2}));  // the hole
  EXPECT_TRUE(region::contains(ring, {kSide / 2, 0}));
}

TEST(RegionContainsIndex, AnswersAsContainsEverywhereIncludingOnTheBoundary) {
  // A ring with a hole, and a closed L beside it: known inside and outside points, then contains()'s
  // own answer at random points, at every vertex and at every edge's midpoint (on the boundary).
  constexpr double kSide = 100.0, kHalfWidth = 5.0;
  region::Paths world = region::strip({{0, 0}, {kSide, 0}, {kSide, kSide}, {0, kSide}, {0, 0}}, kHalfWidth, true);
  const region::Paths l_shape =
      region::closing(region::unite(region::strip({{150, 0}, {250, 0}}, kHalfWidth, false),
                                    region::strip({{155, -5}, {155, 100}}, kHalfWidth, false)),
                      8.0);
  world.insert(world.end(), l_shape.begin(), l_shape.end());
  const region::ContainsIndex index(world, 0.7);
  EXPECT_FALSE(index.contains({kSide / 2, kSide / 2}));  // the hole
  EXPECT_TRUE(index.contains({kSide / 2, 0}));
  EXPECT_TRUE(index.contains({200, 0}));
  EXPECT_FALSE(index.contains({200, 50}));
  EXPECT_FALSE(index.contains({50, -1000}));  // beyond the bands
  EXPECT_FALSE(index.contains({50, 1000}));

  std::vector<Eigen::Vector2d> probes;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x(-20, 270), y(-20, 120);
  for (int i = 0; i < 20000; ++i) probes.emplace_back(x(rng), y(rng));
  for (const auto& path : world)
    for (size_t i = 0; i < path.size(); ++i) {
      const auto& a = path[i];
      const auto& b = path[(i + 1) % path.size()];
      probes.emplace_back(double(a.X) / region::kScale, double(a.Y) / region::kScale);
      if ((a.X + b.X) % 2 == 0 && (a.Y + b.Y) % 2 == 0)
        probes.emplace_back(double((a.X + b.X) / 2) / region::kScale, double((a.Y + b.Y) / 2) / region::kScale);
    }
  int inside = 0;
  for (const auto& p : probes) {
    ASSERT_EQ(index.contains(p), region::contains(world, p)) << p.transpose();
    inside += index.contains(p);
  }
  EXPECT_GT(inside, 1000);  // the probes did reach both answers
  EXPECT_LT(inside, int(probes.size()) - 1000);
}

TEST(RegionClosing, FilletAtInnerCornerOfLShape) {
  // Two perpendicular strips forming an L: one inner (concave) corner at (h, h). Closing with radius r
  // fills it with a circular fillet of area r^2 (1 - pi/4) and leaves the convex corners alone.
  constexpr double kHalfWidth = 5.0, kLength = 100.0, kRadius = 8.0;
  const region::Paths horizontal = region::strip({{-kHalfWidth, 0}, {kLength, 0}}, kHalfWidth, false);
  const region::Paths vertical = region::strip({{0, -kHalfWidth}, {0, kLength}}, kHalfWidth, false);
  const region::Paths l_shape = region::unite(horizontal, vertical);
  const double l_area = 2 * (kLength + kHalfWidth) * 2 * kHalfWidth - 4 * kHalfWidth * kHalfWidth;
  ASSERT_NEAR(region::area(l_shape), l_area, 1e-6);

  const region::Paths closed = region::closing(l_shape, kRadius);
  const double fillet = kRadius * kRadius * kFilletFraction;
  EXPECT_NEAR(region::area(closed) - l_area, fillet, 0.01 * fillet);
  // The fillet's middle is filled, the point beyond the arc is not.
  const Eigen::Vector2d corner(kHalfWidth, kHalfWidth), diagonal = Eigen::Vector2d(1, 1).normalized();
  const double arc_distance = kRadius * (std::sqrt(2.0) - 1);  // corner to arc along the diagonal
  EXPECT_TRUE(region::contains(closed, corner + diagonal * 0.5 * arc_distance));
  EXPECT_FALSE(region::contains(closed, corner + diagonal * 1.5 * arc_distance));
  // The outer (convex) corner stays sharp.
  EXPECT_TRUE(region::contains(closed, {-kHalfWidth + 0.01, -kHalfWidth + 0.01}));
}

TEST(RegionClosing, ZeroRadiusIsTheUnion) {
  const region::Paths a = region::rectangle({0, 0}, {1, 0}, 5, 1), b = region::rectangle({4, 0}, {1, 0}, 5, 1);
  EXPECT_NEAR(region::area(region::closing(region::unite(a, b), 0)), 2 * 14, 1e-9);  // 14 m x 2 m
}

TEST(RegionClipLines, RemovesThePartInsideASquare) {
  // A 40 m line through a 10 m square: 30 m left, in two pieces, none of it inside.
  const region::Paths square = region::rectangle({5, 5}, {1, 0}, 5, 5);
  const Polyline2d line{{-10, 5}, {30, 5}};
  constexpr double kRemaining = 30.0;
  const std::vector<Polyline2d> out = region::clip_lines_outside({line}, square);
  ASSERT_EQ(out.size(), 2u);
  double length = 0;
  for (const auto& piece : out) {
    length += polyline_length(piece);
    for (size_t i = 1; i < piece.size(); ++i) EXPECT_FALSE(region::contains(square, 0.5 * (piece[i] + piece[i - 1])));
  }
  EXPECT_NEAR(length, kRemaining, 1e-3);
}

TEST(RegionClipLines, LineOutsideIsKeptWhole) {
  const region::Paths square = region::rectangle({5, 5}, {1, 0}, 5, 5);
  const std::vector<Polyline2d> out = region::clip_lines_outside({{{-10, 20}, {0, 30}, {30, 30}}}, square);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(polyline_length(out[0]), std::sqrt(200.0) + 30, 1e-3);
}

TEST(RegionClipLines, NoRegionKeepsEveryLine) {
  // Clipper alone returns nothing here (a road with no junction and no crosswalk had no paint).
  const std::vector<Polyline2d> out = region::clip_lines_outside({{{0, 0}, {40, 0}}, {{0, 3}, {10, 3}}}, {});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(polyline_length(out[0]), 40, 1e-3);
  EXPECT_NEAR(polyline_length(out[1]), 10, 1e-3);
}

TEST(RegionContains, HoleIsOutside) {
  const region::Paths frame =
      region::subtract(region::rectangle({0, 0}, {1, 0}, 10, 10), region::rectangle({0, 0}, {1, 0}, 5, 5));
  EXPECT_NEAR(region::area(frame), 400 - 100, 1e-9);
  EXPECT_FALSE(region::contains(frame, {0, 0}));
  EXPECT_TRUE(region::contains(frame, {7.5, 0}));
  EXPECT_FALSE(region::contains(frame, {11, 0}));
}

}  // namespace
}  // namespace lidarloop
