// The world generator: road network -> carriageway / curbs / sidewalks -> triangle mesh and curb map.
// Small hand-made worlds have closed-form areas; the campus world is checked against its specification
// (maps/campus/world.yaml header) and against its own exported curb map.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>

#include <gtest/gtest.h>
#include <unistd.h>

#include "common/input_error.hpp"
#include "sim/polyline.hpp"
#include "sim/world_builder.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

constexpr double kFilletFraction = 1.0 - std::numbers::pi / 4.0;  // fillet area / r^2 at a right-angle corner
constexpr double kMillimetre = 1e-3;

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

const std::string kHeader = "name: test\norigin: {lat: 31.2856, lon: 121.2147}\n";
// A world as flat and smooth as a drawing: no crown, no roughness, level sidewalks.
const std::string kFlatHeader =
    kHeader + "geometry: {roughness_class: none, sidewalk_cross_slope: 0}\nroad_defaults: {cross_slope: 0}\n";

MaterialId material(const std::string& name) { return test::materials().id(name, "test"); }

Eigen::Vector3f triangle_normal(const TriangleMesh& mesh, size_t i) {
  const auto& t = mesh.triangles[i];
  return (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
}

Eigen::Vector3d centroid(const TriangleMesh& mesh, size_t i) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (uint32_t v : mesh.triangles[i]) c += mesh.vertices[v].cast<double>() / 3;
  return c;
}

// Curb faces: vertical triangles of curb concrete (the curb tops are the horizontal ones).
std::vector<size_t> curb_faces(const TriangleMesh& mesh) {
  std::vector<size_t> out;
  const MaterialId curb = material("curb_concrete");
  for (size_t i = 0; i < mesh.triangle_count(); ++i) {
    const Eigen::Vector3f n = triangle_normal(mesh, i);
    if (mesh.materials[i] == curb && n.norm() > 0 && std::abs(n.z()) <= 1e-6f * n.norm()) out.push_back(i);
  }
  return out;
}

// Plan-view area of the triangles of one material.
double material_area(const TriangleMesh& mesh, MaterialId m) {
  double total = 0;
  for (size_t i = 0; i < mesh.triangle_count(); ++i)
    if (mesh.materials[i] == m) total += 0.5 * std::abs(double(triangle_normal(mesh, i).z()));
  return total;
}

Eigen::AlignedBox2d bounding_box(const region::Paths& paths) {
  Eigen::AlignedBox2d box;
  for (const auto& path : paths)
    for (const auto& p : region::to_polyline(path, false)) box.extend(p);
  return box;
}

double distance_to_polyline(const Polyline2d& line, const Eigen::Vector2d& p) {
  return (sample_polyline(line, project_onto_polyline(line, p)).point - p).norm();
}

// The builder's error must be an InputError starting with "where: " and containing `what`.
void expect_build_error(const std::string& yaml, const std::string& where, const std::string& what) {
  try {
    test::world_from_yaml(yaml, "w.yaml");
    ADD_FAILURE() << "no error; expected " << where << ": ..." << what;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(where + ": ", 0), 0u) << "expected the location " << where << " in: " << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << "expected '" << what << "' in: " << msg;
  }
}

// ---------------------------------------------------------------------------------------------- small worlds

constexpr double kWidth = 8.0, kLength = 120.0;

TEST(WorldBuilder, StraightRoadCarriagewayAndCurbRing) {
  const World w = test::world_from_yaml(kHeader + "roads:\n  - {name: main, points: [[0, 0], [" + num(kLength) +
                                        ", 0]], width: " + num(kWidth) + "}\n");
  EXPECT_NEAR(region::area(w.carriageway), kWidth * kLength, 0.005 * kWidth * kLength);
  // The asphalt triangles cover exactly the carriageway.
  EXPECT_NEAR(material_area(w.mesh, material("asphalt")), region::area(w.carriageway), 0.005 * kWidth * kLength);

  // One closed curb ring around it (first point repeated), spanning L x W.
  ASSERT_EQ(w.curbs.size(), 1u);
  const Polyline2d& ring = w.curbs[0];
  ASSERT_GE(ring.size(), 5u);
  EXPECT_EQ(ring.front(), ring.back());
  Eigen::AlignedBox2d box;
  for (const auto& p : ring) box.extend(p);
  EXPECT_NEAR(box.min().x(), 0.0, kMillimetre);
  EXPECT_NEAR(box.max().x(), kLength, kMillimetre);
  EXPECT_NEAR(box.min().y(), -kWidth / 2, kMillimetre);
  EXPECT_NEAR(box.max().y(), kWidth / 2, kMillimetre);
  // Closing (offset out, then in) chamfers convex corners slightly: the eroded polygonal arc (5 mm arc
  // tolerance) leaves a cut ~15 cm long and under 1 cm deep, shortening the ring by ~1 cm per corner.
  constexpr double kCornerTolerance = 0.01, kPerimeterTolerance = 0.1;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, -kWidth / 2), Eigen::Vector2d(kLength, -kWidth / 2),
                                        Eigen::Vector2d(kLength, kWidth / 2), Eigen::Vector2d(0, kWidth / 2)})
    EXPECT_LT(distance_to_polyline(ring, corner), kCornerTolerance) << corner.transpose();
  EXPECT_NEAR(polyline_length(ring), 2 * (kLength + kWidth), kPerimeterTolerance);
}

TEST(WorldBuilder, GroundSurfacesTileTheBoundsWithoutOverlap) {
  // Asphalt, curb tops, sidewalks and grass partition the world's rectangle: their areas add up to it,
  // and the asphalt is the carriageway.
  const World w = test::world_from_yaml(kHeader + "roads:\n  - {name: main, points: [[0, 0], [" + num(kLength) +
                                        ", 0]], width: " + num(kWidth) + "}\n");
  double ground = 0;
  for (const char* name : {"asphalt", "sidewalk", "grass"}) ground += material_area(w.mesh, material(name));
  ground += material_area(w.mesh, material("curb_concrete"));  // vertical faces add nothing in plan view
  const double bounds = w.bounds.volume();
  EXPECT_NEAR(ground, bounds, 1e-4 * bounds);
  EXPECT_NEAR(material_area(w.mesh, material("asphalt")), region::area(w.carriageway), 1e-3);
}

TEST(WorldBuilder, TIntersectionHasRoundedCorners) {
  // Road b leaves road a at a right angle: one carriageway whose two inner corners are filled with
  // fillets of the corner radius, so its area is the union of the strips + 2 r^2 (1 - pi/4).
  constexpr double kRadius = 6.0, kStemEnd = 60.0, kStemX = 50.0;
  const World w = test::world_from_yaml(
      kHeader + "geometry: {corner_radius: " + num(kRadius) + "}\nroads:\n" + "  - {name: a, points: [[0, 0], [" +
      num(kLength) + ", 0]], width: " + num(kWidth) + "}\n  - {name: b, points: [[" + num(kStemX) + ", 0], [" +
      num(kStemX) + ", " + num(kStemEnd) + "]], width: " + num(kWidth) + "}\n");
  ASSERT_EQ(w.carriageway.size(), 1u) << "one region, no holes";
  EXPECT_EQ(w.curbs.size(), 1u);
  const double strips = kLength * kWidth + kWidth * (kStemEnd - kWidth / 2);
  const double fillets = 2 * kRadius * kRadius * kFilletFraction;
  EXPECT_NEAR(region::area(w.carriageway) - strips, fillets, 0.02 * fillets);
  // The fillet is round: the inner corner's diagonal is paved up to the arc, not beyond.
  const Eigen::Vector2d corner(kStemX - kWidth / 2, kWidth / 2), diagonal = Eigen::Vector2d(-1, 1).normalized();
  const double to_arc = kRadius * (std::sqrt(2.0) - 1);
  EXPECT_TRUE(region::contains(w.carriageway, corner + 0.5 * to_arc * diagonal));
  EXPECT_FALSE(region::contains(w.carriageway, corner + 1.5 * to_arc * diagonal));
}

TEST(WorldBuilder, CurbFacesRiseFromAsphaltToCurbHeight) {
  constexpr double kCurbHeight = 0.2;
  const World w = test::world_from_yaml(kFlatHeader + "roads:\n  - {name: main, points: [[0, 0], [" + num(kLength) +
                                        ", 0]], curb_height: " + num(kCurbHeight) + "}\n");
  const std::vector<size_t> faces = curb_faces(w.mesh);
  ASSERT_GE(faces.size(), 8u);  // at least two triangles per side of the ring
  double face_length = 0;
  float lowest = INFINITY, highest = -INFINITY;
  for (size_t i : faces) {
    for (uint32_t v : w.mesh.triangles[i])
      lowest = std::min(lowest, w.mesh.vertices[v].z()), highest = std::max(highest, w.mesh.vertices[v].z());
    face_length += triangle_normal(w.mesh, i).norm();  // 2 x area = base length x height
  }
  EXPECT_EQ(lowest, 0.0f);
  EXPECT_FLOAT_EQ(highest, float(kCurbHeight));
  face_length /= kCurbHeight;
  // The faces (two triangles per quad) run all around the curb ring.
  EXPECT_NEAR(face_length / 2, polyline_length(w.curbs[0]), 0.01);
}

TEST(WorldBuilder, CurbFacesFaceTheCarriageway) {
  // Each face's outward normal points into the carriageway (the side a LiDAR on the road sees).
  const World w =
      test::world_from_yaml(kHeader + "roads:\n  - {name: main, points: [[0, 0], [" + num(kLength) + ", 0]]}\n");
  const std::vector<size_t> faces = curb_faces(w.mesh);
  ASSERT_FALSE(faces.empty());
  for (size_t i : faces) {
    const Eigen::Vector3d n = triangle_normal(w.mesh, i).cast<double>().normalized();
    const Eigen::Vector2d probe = centroid(w.mesh, i).head<2>() + 0.05 * n.head<2>();
    EXPECT_TRUE(region::contains(w.carriageway, probe)) << "curb face " << i << " faces away from the road";
  }
}

TEST(WorldBuilder, CurbHeightFollowsTheNearestRoad) {
  // A T of two roads with different curb heights: far from the junction, the curb faces and the
  // sidewalk along each road stand at that road's own curb height.
  constexpr double kLow = 0.12, kHigh = 0.25, kStemX = 50.0, kStemEnd = 80.0, kFarFromJunction = 20.0;
  const std::string yaml = kFlatHeader + "roads:\n  - {name: a, points: [[0, 0], [" + num(kLength) +
                           ", 0]], curb_height: " + num(kLow) + "}\n  - {name: b, points: [[" + num(kStemX) +
                           ", 0], [" + num(kStemX) + ", " + num(kStemEnd) + "]], curb_height: " + num(kHigh) + "}\n";
  const WorldDescription desc = parse_world_description(yaml, "w.yaml");
  const World w = build_world(desc, test::materials(), test::data_path("assets/actors"));
  const Polyline2d &a = desc.road("a")->centreline, &b = desc.road("b")->centreline;
  const Eigen::Vector2d junction(kStemX, 0);

  // The face is meshed in bands up its height: the highest vertex along each road is its curb's top.
  int faces_a = 0, faces_b = 0;
  float top_a = 0, top_b = 0;
  for (size_t i : curb_faces(w.mesh)) {
    const Eigen::Vector2d c = centroid(w.mesh, i).head<2>();
    if ((c - junction).norm() < kFarFromJunction) continue;
    const bool near_a = distance_to_polyline(a, c) < distance_to_polyline(b, c);
    for (uint32_t v : w.mesh.triangles[i]) {
      float& top = near_a ? top_a : top_b;
      top = std::max(top, w.mesh.vertices[v].z());
    }
    ++(near_a ? faces_a : faces_b);
  }
  EXPECT_GT(faces_a, 0);
  EXPECT_GT(faces_b, 0);
  EXPECT_FLOAT_EQ(top_a, float(kLow));
  EXPECT_FLOAT_EQ(top_b, float(kHigh));

  // The sidewalk surface continues from the curb top at the same height.
  int sidewalks_a = 0, sidewalks_b = 0;
  const MaterialId sidewalk = material("sidewalk");
  for (size_t i = 0; i < w.mesh.triangle_count(); ++i) {
    if (w.mesh.materials[i] != sidewalk) continue;
    const Eigen::Vector2d c = centroid(w.mesh, i).head<2>();
    if ((c - junction).norm() < kFarFromJunction) continue;
    const bool near_a = distance_to_polyline(a, c) < distance_to_polyline(b, c);
    for (uint32_t v : w.mesh.triangles[i]) EXPECT_EQ(w.mesh.vertices[v].z(), float(near_a ? kLow : kHigh));
    ++(near_a ? sidewalks_a : sidewalks_b);
  }
  EXPECT_GT(sidewalks_a, 0);
  EXPECT_GT(sidewalks_b, 0);
}

// A straight road along x (width 8: carriageway |y| <= 4, sidewalks to |y| <= 7) and one extra list,
// whose first entry is on line 6.
std::string road_with(const std::string& extra) {
  return kHeader + "roads:\n  - {name: main, points: [[0, 0], [100, 0]], width: 8, sidewalk_width: 3}\n" + extra;
}

TEST(WorldBuilder, BuildingBesideTheSidewalkBuilds) {
  const World w = test::world_from_yaml(road_with("buildings:\n  - {centre: [50, 12], size: [10, 4]}\n"));
  EXPECT_GT(material_area(w.mesh, material("building")), 0.0);
}

TEST(WorldBuilder, BuildingOnTheCarriagewayIsAnError) {
  // The second building (line 7; column 5 is its opening brace) is the one on the road.
  expect_build_error(
      road_with("buildings:\n  - {centre: [50, 12], size: [10, 4]}\n  - {centre: [50, 2], size: [10, 10]}\n"),
      "w.yaml:7:5", "building overlaps the road or its sidewalks");
}

TEST(WorldBuilder, BuildingOnTheSidewalkIsAnError) {
  expect_build_error(road_with("buildings:\n  - {centre: [50, -8], size: [10, 4]}\n"), "w.yaml:6:5",
                     "building overlaps the road or its sidewalks");
}

TEST(WorldBuilder, UnknownBuildingMaterialIsAnError) {
  expect_build_error(road_with("buildings:\n  - centre: [50, 30]\n    size: [10, 10]\n    material: unobtainium\n"),
                     "w.yaml:6:5", "unknown material 'unobtainium'");
}

TEST(WorldBuilder, ParkedVehicleOnTheCarriagewayIsAnError) {
  expect_build_error(road_with("parked_vehicles:\n  - {position: [50, 1], type: bus}\n"), "w.yaml:6:5",
                     "overlaps the carriageway");
}

// ---------------------------------------------------------------------------------------------- campus

// The campus world is built once for all its tests (a second or so).
class WorldBuilderCampus : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    desc_ = new WorldDescription(load_world_description(test::data_path("maps/campus/world.yaml")));
    world_ = new World(build_world(*desc_, test::materials(), test::data_path("assets/actors")));
  }
  static void TearDownTestSuite() {
    delete world_;
    delete desc_;
    world_ = nullptr;
    desc_ = nullptr;
  }
  static const WorldDescription& desc() { return *desc_; }
  static const World& world() { return *world_; }

 private:
  static inline WorldDescription* desc_ = nullptr;
  static inline World* world_ = nullptr;
};

TEST_F(WorldBuilderCampus, MeshIsWellFormed) {
  const TriangleMesh& mesh = world().mesh;
  ASSERT_EQ(mesh.materials.size(), mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangle_count(); ++i) {
    for (uint32_t v : mesh.triangles[i]) ASSERT_LT(v, mesh.vertices.size()) << "triangle " << i;
    ASSERT_LT(mesh.materials[i], test::materials().size()) << "triangle " << i;
  }
  for (const auto& v : mesh.vertices) ASSERT_TRUE(v.allFinite());
}

TEST_F(WorldBuilderCampus, BoundsContainTheMesh) {
  const Eigen::AlignedBox2d& b = world().bounds;
  for (const auto& v : world().mesh.vertices)
    ASSERT_TRUE(b.contains(v.head<2>().cast<double>())) << v.transpose() << " is outside the world's bounds";
}

TEST_F(WorldBuilderCampus, SizeIsAbout600By400) {
  constexpr double kSpecWidth = 600, kSpecHeight = 400, kTolerance = 0.10;
  const Eigen::Vector2d size = bounding_box(world().carriageway).sizes();
  EXPECT_NEAR(size.x(), kSpecWidth, kTolerance * kSpecWidth);
  EXPECT_NEAR(size.y(), kSpecHeight, kTolerance * kSpecHeight);
}

TEST_F(WorldBuilderCampus, HasAtLeastFourIntersections) {
  constexpr int kMinIntersections = 4;
  constexpr double kMinOverlap = 1.0;  // m^2; roads that merely touch end to end do not count
  int intersections = 0;
  const auto& roads = desc().roads;
  for (size_t i = 0; i < roads.size(); ++i)
    for (size_t j = i + 1; j < roads.size(); ++j) {
      const region::Paths overlap =
          region::intersect(region::strip(roads[i].centreline, roads[i].width / 2, roads[i].closed),
                            region::strip(roads[j].centreline, roads[j].width / 2, roads[j].closed));
      if (region::area(overlap) > kMinOverlap) ++intersections;
    }
  EXPECT_GE(intersections, kMinIntersections);
}

TEST_F(WorldBuilderCampus, HasLongStraightWithCrosswalks) {
  constexpr double kMinStraight = 300.0, kOnLine = 0.01;
  constexpr int kMinCrosswalks = 2;
  int best_crosswalks = -1;
  for (const auto& road : desc().roads)
    for (size_t k = 1; k < road.centreline.size(); ++k) {
      const Polyline2d segment{road.centreline[k - 1], road.centreline[k]};
      if (polyline_length(segment) < kMinStraight) continue;
      int on_it = 0;
      for (const auto& c : desc().crosswalks)
        if (c.road == road.name &&
            distance_to_polyline(segment, sample_polyline(road.centreline, c.at).point) < kOnLine)
          ++on_it;
      best_crosswalks = std::max(best_crosswalks, on_it);
    }
  ASSERT_GE(best_crosswalks, 0) << "no straight centreline segment of " << kMinStraight << " m";
  EXPECT_GE(best_crosswalks, kMinCrosswalks);
}

TEST_F(WorldBuilderCampus, HasOneWayRoadAndCurve) {
  bool one_way = false, curve = false;
  for (const auto& road : desc().roads) {
    one_way = one_way || road.one_way;
    curve = curve || road.smoothing_radius > 0;
  }
  EXPECT_TRUE(one_way);
  EXPECT_TRUE(curve);
}

TEST_F(WorldBuilderCampus, SmoothedRoadCornersAreRounded) {
  // A corner rounded with radius R that turns by theta is R (1 / cos(theta / 2) - 1) from the arc; ask
  // for at least half of that, so any real rounding passes and a sharp corner (distance 0) does not.
  int corners = 0;
  for (const auto& road : desc().roads) {
    if (road.smoothing_radius <= 0) continue;
    const size_t n = road.points.size() - (road.closed ? 1 : 0);  // closed: the last point repeats the first
    for (size_t k = road.closed ? 0 : 1; k < (road.closed ? n : n - 1); ++k) {
      const Eigen::Vector2d p = road.points[k], prev = road.points[(k + n - 1) % n], next = road.points[(k + 1) % n];
      const double theta = std::acos(std::clamp((p - prev).normalized().dot((next - p).normalized()), -1.0, 1.0));
      if (theta < 1e-3) continue;
      const double expected = road.smoothing_radius * (1 / std::cos(theta / 2) - 1);
      EXPECT_GT(distance_to_polyline(road.centreline, p), 0.5 * expected)
          << "road '" << road.name << "' corner " << k << " at " << p.transpose() << " is not rounded";
      ++corners;
    }
  }
  EXPECT_GE(corners, 4);  // the loop's four corners
}

TEST_F(WorldBuilderCampus, HasAllSurfaceMaterials) {
  const std::set<MaterialId> used(world().mesh.materials.begin(), world().mesh.materials.end());
  for (const char* name : {"asphalt", "lane_paint", "crosswalk_paint", "curb_concrete", "sidewalk", "grass", "building",
                           "vegetation", "retro_reflector", "metal"})
    EXPECT_TRUE(used.count(material(name))) << "no " << name << " triangles in the campus mesh";
}

// Vertical faces of vertical curbs: round an intersection's corner where the profile changes, and
// along a sloped curb's flares, the band twists between cross-sections and its triangles are neither.
std::vector<size_t> uniform_curb_faces(const World& w) {
  std::vector<size_t> out;
  for (size_t i : curb_faces(w.mesh)) {
    const Eigen::Vector2d c = centroid(w.mesh, i).head<2>();
    std::set<CurbProfile> near;
    for (const auto& ring : w.curb_band->rings())
      for (const CurbStation& s : ring)
        if ((s.point - c).norm() < 1.0) near.insert(s.profile);
    if (near == std::set<CurbProfile>{CurbProfile::vertical}) out.push_back(i);
  }
  return out;
}

TEST_F(WorldBuilderCampus, CurbFacesFaceTheCarriageway) {
  // Holds for the outer ring and for the inner rings (the blocks between roads) alike.
  const std::vector<size_t> faces = uniform_curb_faces(world());
  ASSERT_FALSE(faces.empty());
  EXPECT_GT(world().curbs.size(), 1u) << "the campus road network encloses blocks: inner curb rings";
  for (size_t i : faces) {
    const Eigen::Vector3d n = triangle_normal(world().mesh, i).cast<double>().normalized();
    const Eigen::Vector2d probe = centroid(world().mesh, i).head<2>() + 0.05 * n.head<2>();
    EXPECT_TRUE(region::contains(world().carriageway, probe)) << "curb face " << i << " faces away from the road";
  }
}

TEST_F(WorldBuilderCampus, GeoJsonCurbsCoincideWithMeshedCurbEdges) {
  // Export the curb map, read it back (WGS-84 and back), and find the foot of every curb face in it.
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("lidarloop_test_campus_curbs_" + std::to_string(::getpid()) + ".geojson"))
                               .string();
  write_curb_map(path, world().curb_map());
  const CurbMap map = read_curb_map(path);
  std::filesystem::remove(path);
  EXPECT_EQ(map.world, "campus");
  ASSERT_EQ(map.curbs.size(), world().curbs.size());

  // Hash the read-back vertices on a 1 cm grid; a lookup checks the 3 x 3 neighbouring cells.
  constexpr double kCell = 0.01;
  auto key = [&](long ix, long iy) { return (ix << 32) ^ (iy & 0xffffffffL); };
  std::unordered_multimap<long, Eigen::Vector2d> cells;
  for (const auto& curb : map.curbs)
    for (const auto& p : curb) cells.emplace(key(std::lround(p.x() / kCell), std::lround(p.y() / kCell)), p);
  auto nearest = [&](const Eigen::Vector2d& q) {
    double best = INFINITY;
    const long ix = std::lround(q.x() / kCell), iy = std::lround(q.y() / kCell);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        auto [lo, hi] = cells.equal_range(key(ix + dx, iy + dy));
        for (auto it = lo; it != hi; ++it) best = std::min(best, (it->second - q).norm());
      }
    return best;
  };

  size_t checked = 0;
  for (size_t i : uniform_curb_faces(world()))
    for (uint32_t v : world().mesh.triangles[i]) {
      const Eigen::Vector3f& p = world().mesh.vertices[v];
      ++checked;
      EXPECT_LT(nearest(p.head<2>().cast<double>()), kMillimetre) << "curb face foot " << p.transpose();
    }
  EXPECT_GT(checked, 100u);
}

// ---------------------------------------------------------------------------------------------- large world

TEST(WorldBuilderLarge, IsAbout1800By1200AndBuilds) {
  const std::string path = test::data_path("maps/large/world.yaml");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " does not exist yet";
  constexpr double kSpecWidth = 1800, kSpecHeight = 1200, kTolerance = 0.10;
  const WorldDescription desc = load_world_description(path);
  const World w = build_world(desc, test::materials(), test::data_path("assets/actors"));
  const Eigen::Vector2d size = bounding_box(w.carriageway).sizes();
  EXPECT_NEAR(size.x(), kSpecWidth, kTolerance * kSpecWidth);
  EXPECT_NEAR(size.y(), kSpecHeight, kTolerance * kSpecHeight);
  EXPECT_FALSE(w.curbs.empty());
  EXPECT_FALSE(curb_faces(w.mesh).empty());
  EXPECT_GT(material_area(w.mesh, material("asphalt")), 0.0);
}

}  // namespace
}  // namespace lidarloop
