#pragma once
// The Embree scene a LiDAR casts into: the static world plus moving actors.
//
// Two levels: the world mesh and each actor type are built once as their own BVHs; the top-level
// scene holds only instances of them. Moving an actor updates its instance transform and recommits
// the top level (a handful of boxes), never the static world.
//
// Actors can also move during a scan: set_actor_motion() gives an instance one transform per
// keyframe (Embree instance motion blur), and each ray carries its time within the keyframes' span, so
// a whole scan is cast in one parallel pass with every actor where it was at that ray's instant.
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <Eigen/Geometry>

#include "sim/triangle_mesh.hpp"

namespace lidarloop {

// The sets of Embree kernels a scene can be pinned to. `native`: Embree's own choice, unpinned (the only
// one off x86, where there is no other set to pin to).
inline constexpr const char* kRayIsaSse42 = "sse4.2";
inline constexpr const char* kRayIsaAvx2 = "avx2";
inline constexpr const char* kRayIsaAvx512 = "avx512";
inline constexpr const char* kRayIsaNative = "native";

// The kernels ray casting is pinned to on this machine: AVX2's where the processor has AVX2 and FMA, else
// SSE4.2's (native off x86). Scans are the same bytes wherever the set is the same. The environment
// variable LIDARLOOP_RAY_ISA picks another (sse4.2, avx2, avx512: AVX-512's cast faster still where the
// processor has it, but its scans differ from AVX2's in the last bits; native); InputError for a name
// not in that list or a processor without it.
std::string ray_isa();

struct Ray {
  Eigen::Vector3f origin, direction;  // world frame, unit direction
  float time = 0;                     // 0..1 across the actors' keyframes
};

struct RayHit {
  float range = 0;                  // along the (unit) ray direction
  Eigen::Vector3f normal{0, 0, 1};  // unit, world frame
  MaterialId material = 0;
  int actor = -1;  // the actor hit (add_actor's id), -1 for the static world
};

class RayScene {
 public:
  // How the world's vertices and triangles reach Embree. `copied`: into buffers of Embree's own, so the
  // mesh may go once the scene is made. `shared`: Embree reads the mesh's own arrays
  // (rtcSetSharedGeometryBuffer) and keeps no copy of them, a saving of 86 MB on the `large` world; the
  // mesh must then outlive the scene unchanged. Embree reads the last vertex with a 16-byte load, 4
  // bytes past it: a mesh whose vertex array has no spare capacity for that is copied all the same.
  enum class MeshBuffers { copied, shared };
  // threads = 0: Embree chooses (all cores). The BVH is deterministic whatever the count. `isa`: the
  // kernels (ray_isa(), or another set for a benchmark's peer); InputError for one this processor lacks.
  explicit RayScene(const TriangleMesh& world, int threads = 0, MeshBuffers buffers = MeshBuffers::copied,
                    const std::string& isa = ray_isa());
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  int add_prototype(const TriangleMesh& mesh);  // an actor type; returns its id
  int add_actor(int prototype, const Eigen::Isometry3d& pose);
  void set_actor_pose(int actor, const Eigen::Isometry3d& pose);
  // Poses at evenly spaced keyframes (2 to kMaxKeyframes) spanning ray times 0..1.
  static constexpr int kMaxKeyframes = RTC_MAX_TIME_STEP_COUNT;
  void set_actor_motion(int actor, const std::vector<Eigen::Isometry3d>& keyframes);
  void set_actor_visible(int actor, bool visible);
  size_t actor_count() const { return actors_.size(); }
  // Must be called after adding or moving actors and before casting.
  void commit();

  // Nearest hit of a ray within [tnear, tfar]; thread-safe between commits.
  bool intersect(const Ray& ray, float tnear, float tfar, RayHit& hit) const;
  // The same for up to kPacket rays at once: Embree's packet traversal, much cheaper for coherent rays.
  // found[k] tells whether ray k hit; hits[k] is set only then.
  static constexpr int kPacket = 16;
  void intersect8(const Ray* rays, int count, float tnear, float tfar, RayHit* hits, bool* found) const;
  // Whether the static world alone (no actors) stops the ray within [tnear, tfar]: what a ray that
  // met an actor would have met without the traffic.
  bool world_occludes(const Ray& ray, float tnear, float tfar) const;

  RTCScene top_level() const { return top_; }  // for benchmarking bare rtcIntersect1
  size_t world_triangles() const { return world_triangles_; }

 private:
  struct Prototype {
    RTCScene scene;
    std::vector<MaterialId> materials;
  };
  struct Actor {
    int prototype;
    RTCGeometry instance;
    unsigned geom_id;
    std::vector<Eigen::Matrix3f> rotations;  // per keyframe, to bring object-space normals to the world
    bool visible;
    int actor;  // its id, -1 for the static world's instance
  };
  Prototype make_prototype(const TriangleMesh& mesh, MeshBuffers buffers) const;
  RayHit make_hit(unsigned inst_id, unsigned prim_id, float tfar, const Eigen::Vector3f& ng, float time) const;

  RTCDevice device_ = nullptr;
  RTCScene top_ = nullptr;
  std::vector<Prototype> prototypes_;  // [0] is the static world
  std::vector<Actor> instances_;       // [0] is the static world's instance
  std::vector<int> actors_;            // actor id -> index into instances_
  std::vector<int> instance_of_geom_;  // top-level geomID -> index into instances_
  size_t world_triangles_ = 0;
};

}  // namespace lidarloop
