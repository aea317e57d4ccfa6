// RayScene's mesh buffers: Embree reading the mesh's own arrays casts the same rays as its copy.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "sim/ray_scene.hpp"
#include "tests/sim/test_support.hpp"

namespace lidarloop {
namespace {

// Ground, walls and a pole: faces at many angles, shared edges and corners for rays to find.
TriangleMesh street() {
  TriangleMesh mesh = test::flat_ground(30);
  test::add_wall(mesh, {10, 0}, {0.3f, 8}, 6);
  test::add_wall(mesh, {-6, 5}, {4, 0.2f}, 3, "curb_concrete");
  add_frustum(mesh, {3, -4, 0}, 0.1f, 0.08f, 5, 12, test::materials().id("metal", "test"));
  return mesh;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every ray of a fan from above the street hits the same thing at the same float in both scenes.
void expect_same_hits(const RayScene& a, const RayScene& b) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Ray ray{{u(rng) * 5, u(rng) * 5, 1.8f}, Eigen::Vector3f(u(rng), u(rng), u(rng) - 0.3f).normalized(), 0};
    RayHit ha, hb;
    const bool found_a = a.intersect(ray, 0, 100, ha), found_b = b.intersect(ray, 0, 100, hb);
    ASSERT_EQ(found_a, found_b) << "ray " << i;
    if (!found_a) continue;
    ++hits;
    EXPECT_TRUE(same_bits(ha.range, hb.range)) << "ray " << i;
    EXPECT_EQ(ha.material, hb.material) << "ray " << i;
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_bits(ha.normal[k], hb.normal[k])) << "ray " << i;
  }
  EXPECT_GT(hits, 10000);
}

TEST(RaySceneBuffers, SharedMeshCastsTheSameRaysAsACopy) {
  const TriangleMesh mesh = street();
  ASSERT_GT(mesh.vertices.capacity(), mesh.vertices.size());  // room for Embree's 16-byte load
  const RayScene copied(mesh), shared(mesh, 0, RayScene::MeshBuffers::shared);
  expect_same_hits(copied, shared);
}

TEST(RaySceneBuffers, AMeshWithoutSpareCapacityIsCopiedAndCastsTheSame) {
  TriangleMesh mesh = street();
  mesh.vertices.shrink_to_fit();  // may leave it full: then the scene must copy
  const RayScene copied(mesh), shared(mesh, 0, RayScene::MeshBuffers::shared);
  expect_same_hits(copied, shared);
}

}  // namespace
}  // namespace lidarloop
