// The campus HD map as `lidarloop map campus` builds it (found in, or added to, the build folder's map
// cache): lane paint and crosswalks stand out of the asphalt in the intensity layer. Which cells are
// paint and which asphalt is read off the world itself, by casting a ray straight down at each cell.
#include <iostream>

#include <gtest/gtest.h>

#include "localizer/hd_map.hpp"
#include "mapping/map_cache.hpp"
#include "sim/ray_scene.hpp"
#include "sim/world_assets.hpp"

namespace lidarloop {
namespace {

TEST(CampusMap, PaintCellsAreAtLeastThreeTimesBrighterThanAsphalt) {
  const LoadedWorld w = load_world("campus");
  const MapLocation loc = ensure_map("campus", MappingOptions{}, false);
  HdMap map = open_hd_map(loc.dir, "campus");
  const RayScene scene(w.world.mesh);
  const MaterialId asphalt = w.materials.id("asphalt", "test"), lane = w.materials.id("lane_paint", "test"),
                   zebra = w.materials.id("crosswalk_paint", "test");
  const double res = map.intensity.header().resolution_m;
  // The material under a point, seen from above.
  auto material_at = [&](double x, double y) -> int {
    RayHit hit;
    if (!scene.intersect({{float(x), float(y), 5.0f}, {0, 0, -1}}, 0.0f, 10.0f, hit)) return -1;
    return hit.material;
  };
  // Whether the material at the cell centre is also found `reach` metres around it: paint cells need
  // their middle on paint (lines are 0.15 m wide, narrower than a cell), asphalt cells a clear margin.
  auto uniform_material = [&](double x, double y, double reach) {
    const int m = material_at(x, y);
    for (auto [dx, dy] : {std::pair{reach, 0.0}, {-reach, 0.0}, {0.0, reach}, {0.0, -reach}})
      if (material_at(x + dx, y + dy) != m) return -1;
    return m;
  };
  constexpr double kPaintReach = 0.05, kAsphaltReach = 0.3;
  double sum[3] = {0, 0, 0};
  int n[3] = {0, 0, 0};                        // asphalt, lane paint, crosswalk paint
  constexpr double kAlong = 0.5, kInto = 5.0;  // m: walk along every curb, up to 5 m into the road
  for (const auto& line : w.world.curbs)
    for (size_t i = 1; i < line.size(); ++i) {
      const Eigen::Vector2d d = line[i] - line[i - 1];
      const Eigen::Vector2d left = Eigen::Vector2d(-d.y(), d.x()).normalized();  // the road is on the left
      for (double along = 0; along < d.norm(); along += kAlong)
        for (double into = 0.3; into < kInto; into += res) {
          const Eigen::Vector2d c = line[i - 1] + d.normalized() * along + left * into;
          const auto cell = map.intensity.cell(c);
          if (!cell || cell->count < 3) continue;
          const int centre = material_at(c.x(), c.y());
          const int m = uniform_material(c.x(), c.y(), centre == asphalt ? kAsphaltReach : kPaintReach);
          const int k = m == asphalt ? 0 : m == lane ? 1 : m == zebra ? 2 : -1;
          if (k >= 0) sum[k] += cell->mean, ++n[k];
        }
    }
  ASSERT_GT(n[0], 1000);
  ASSERT_GT(n[1], 50);
  ASSERT_GT(n[2], 20);
  const double a = sum[0] / n[0], l = sum[1] / n[1], z = sum[2] / n[2];
  std::cout << "[ figures  ] mean intensity: asphalt " << a << " (" << n[0] << " cells), lane paint " << l << " ("
            << n[1] << "), crosswalk " << z << " (" << n[2] << ")\n";
  EXPECT_GT(l, 3 * a);
  EXPECT_GT(z, 3 * a);
}

}  // namespace
}  // namespace lidarloop
