// Scans of the generated campus: the curbs a localizer will look for are where the map says, at the
// height the world description gives them.
#include <gtest/gtest.h>

#include "sim/lidar_scanner.hpp"
#include "sim/polyline.hpp"
#include "sim/world_assets.hpp"
#include "test_support.hpp"

namespace lidarloop {
namespace {

const LoadedWorld& campus() {
  static const LoadedWorld w = load_world(test::data_path("maps/campus/world.yaml"));
  return w;
}

// World-frame points of one noiseless scan from a vehicle standing at (x, y) heading east.
std::vector<Eigen::Vector3d> scan_world(double x, double y) {
  RayScene scene(campus().world.mesh);
  const Hdl32eConfig config = test::noiseless_hdl32e();
  const LidarScanner scanner(config, campus().materials);
  const Eigen::Isometry3d vehicle(Eigen::Translation3d(x, y, 0));
  const PointCloud cloud = scanner.scan(scene, constant_twist(vehicle, 0, 0, 0), 0, 1);
  std::vector<Eigen::Vector3d> out;
  const Eigen::Isometry3d sensor = vehicle * config.mount();
  // Where each ray met the world (not where the driver reports it, up to 0.13 deg round: Hdl32e tests).
  for (const auto& p : cloud.points) out.push_back(sensor * test::fired_point(p, config));
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

// The curb's cross-section nearest to a point.
const CurbStation& nearest_station(const Eigen::Vector2d& p) {
  const CurbStation* best = nullptr;
  for (const auto& ring : campus().world.curb_band->rings())
    for (const CurbStation& c : ring)
      if (!best || (c.point - p).squaredNorm() < (best->point - p).squaredNorm()) best = &c;
  return *best;
}

TEST(CampusScan, CurbFacesShowTheirHeightAboveThePavement) {
  // On the south straight of the loop (centreline y = 0), away from crosswalks and driveways.
  const RoadSpec& loop = *campus().description.road("loop");
  const double curb_y = -loop.width / 2;
  const auto points = scan_world(220, -2.25);
  const CurbStation& here = nearest_station({220, curb_y});
  ASSERT_FALSE(here.cut);
  const GroundHeight ground = campus().world.ground();
  std::vector<double> road, top, face;
  for (const auto& p : points) {
    if (std::abs(p.x() - 220) > 8) continue;
    const double d = p.y() - curb_y;  // > 0 on the carriageway
    if (d > loop.gutter_width + 0.2 && d < 1.5) road.push_back(p.z() - ground(p.head<2>()));
    if (d < -0.02 && d > -0.12) top.push_back(p.z() - here.bottom_z);
    if (std::abs(d) < 0.005) face.push_back(p.z() - here.bottom_z);
  }
  ASSERT_GT(road.size(), 50u);
  ASSERT_GT(top.size(), 10u);
  ASSERT_GT(face.size(), 10u);
  EXPECT_NEAR(median(road), 0.0, 0.01);  // the scan sees the crowned, rough pavement where it is
  EXPECT_NEAR(median(top), here.height, 0.01);
  // Points on the face itself span the step and never rise above the curb.
  EXPECT_NEAR(*std::max_element(face.begin(), face.end()), here.height, 0.01);
  EXPECT_LT(*std::min_element(face.begin(), face.end()), here.height - 0.05);
}

TEST(CampusScan, CurbsInTheScanLieOnTheCurbMap) {
  // Every point on a curb face (well between its foot and its top) is within 2 cm of a curb line.
  const auto points = scan_world(300, 150);  // central avenue, near the four-way intersection
  const auto& curbs = campus().world.curbs;
  // Each line's bounding box, grown by the 0.5 m that counts as "on a curb": lines whose box is farther
  // from a point cannot be its curb, and skipping them keeps the test short under the sanitizers.
  std::vector<Eigen::AlignedBox2d> boxes;
  for (const auto& line : curbs) {
    Eigen::AlignedBox2d box;
    for (const auto& q : line) box.extend(q);
    boxes.push_back(box);
  }
  int face_points = 0;
  for (const auto& p : points) {
    // Round the intersection's corners the curb changes profile from road to road: not measured here.
    if (p.head<2>().norm() > 1e4 || std::abs(p.y() - 200) < 15) continue;
    const CurbStation& c = nearest_station(p.head<2>());
    const double rise = p.z() - c.bottom_z;
    if (c.profile != CurbProfile::vertical || rise < 0.2 * c.height || rise > 0.8 * c.height) continue;
    double best = 1e9;
    for (size_t k = 0; k < curbs.size(); ++k) {
      if (boxes[k].exteriorDistance(Eigen::Vector2d(p.head<2>())) > 0.5) continue;
      const double s = project_onto_polyline(curbs[k], p.head<2>());
      best = std::min(best, (sample_polyline(curbs[k], s).point - p.head<2>()).norm());
    }
    if (best > 0.5) continue;  // not a curb (an object's base, a car's tyre)
    ++face_points;
    EXPECT_LT(best, 0.02) << p.transpose() << " station " << c.point.transpose() << " road " << c.road << " s " << c.s
                          << " height " << c.height << " cut " << c.cut.has_value();
  }
  EXPECT_GT(face_points, 30);
}

}  // namespace
}  // namespace lidarloop
