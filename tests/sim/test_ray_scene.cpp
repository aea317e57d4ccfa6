// RayScene's mesh buffers: Embree reading the mesh's own arrays casts the same rays as its copy. Its
// kernels: pinned by ray_isa(), and every set of them finds the same surfaces.
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
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

// LIDARLOOP_RAY_ISA set for one test's span, and put back as it was.
class RayIsaVariable {
 public:
  explicit RayIsaVariable(const char* value) {
    if (const char* old = std::getenv(kName)) old_ = old;
    ::setenv(kName, value, 1);
  }
  ~RayIsaVariable() {
    if (old_)
      ::setenv(kName, old_->c_str(), 1);
    else
      ::unsetenv(kName);
  }

 private:
  static constexpr const char* kName = "LIDARLOOP_RAY_ISA";
  std::optional<std::string> old_;
};

#if defined(__x86_64__)
TEST(RayIsa, PinnedToAvx2WhereTheProcessorHasItAndFma) {
  const RayIsaVariable unset("");
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  EXPECT_EQ(ray_isa(), avx2 ? kRayIsaAvx2 : kRayIsaSse42);
}

TEST(RayIsa, TheVariableMustNameAKnownSet) {
  const RayIsaVariable bad("avx3");
  try {
    ray_isa();
    FAIL() << "no error for an unknown set";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("LIDARLOOP_RAY_ISA=avx3"), std::string::npos) << e.what();
  }
  const RayIsaVariable sse(kRayIsaSse42);
  EXPECT_EQ(ray_isa(), kRayIsaSse42);
}

// A known plane: every set of kernels the processor has puts the street's ground at the range a ray's
// geometry gives (float rounding apart), and the walls, pole and sky where the pinned set does.
TEST(RayIsa, EveryKernelSetFindsTheSameSurfaces) {
  const TriangleMesh mesh = street();
  const RayScene pinned(mesh);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  for (const char* isa : {kRayIsaSse42, kRayIsaAvx2, kRayIsaAvx512}) {
    std::optional<RayScene> other;
    try {
      other.emplace(mesh, 0, RayScene::MeshBuffers::copied, isa);
    } catch (const InputError&) {
      continue;  // not on this processor
    }
    int ground = 0;
    for (int i = 0; i < 5000; ++i) {
      const float ox = u(rng), oy = u(rng), dx = u(rng), dy = u(rng), dz = u(rng);  // in this order
      const Ray ray{{ox * 2, oy * 2, 1.8f}, Eigen::Vector3f(dx, dy, dz - 0.3f).normalized(), 0};
      RayHit a, b;
      const bool found_a = pinned.intersect(ray, 0, 100, a), found_b = other->intersect(ray, 0, 100, b);
      ASSERT_EQ(found_a, found_b) << isa << " ray " << i;
      if (!found_a) continue;
      EXPECT_EQ(a.material, b.material) << isa << " ray " << i;
      EXPECT_NEAR(a.range, b.range, 1e-5f * a.range) << isa << " ray " << i;
      // The ground is z = 0: a ray down from 1.8 m meets it at 1.8 / -d_z unless something stands nearer.
      if (a.normal.z() > 0.999f && ray.direction.z() < -0.05f) {
        EXPECT_NEAR(b.range, 1.8f / -ray.direction.z(), 2e-5f * b.range) << isa << " ray " << i;
        ++ground;
      }
    }
    EXPECT_GT(ground, 1000) << isa;
  }
}
#endif

}  // namespace
}  // namespace lidarloop
