#pragma once
// The Embree scene a LiDAR casts into: the static world plus moving actors.
//
// Two levels: the world mesh and each actor type are built once as their own BVHs; the top-level
// scene holds only instances of them. Moving an actor updates its instance transform and recommits
// the top level (a handful of boxes), never the static world.
#include <vector>

#include <Eigen/Geometry>
#include <embree3/rtcore.h>

#include "sim/triangle_mesh.hpp"

namespace lidarloop {

struct RayHit {
  float range = 0;                // along the (unit) ray direction
  Eigen::Vector3f normal{0, 0, 1};  // unit, world frame
  MaterialId material = 0;
};

class RayScene {
 public:
  // threads = 0: Embree chooses (all cores). The BVH is deterministic whatever the count.
  explicit RayScene(const TriangleMesh& world, int threads = 0);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  int add_prototype(const TriangleMesh& mesh);  // an actor type; returns its id
  int add_actor(int prototype, const Eigen::Isometry3d& pose);
  void set_actor_pose(int actor, const Eigen::Isometry3d& pose);
  void set_actor_visible(int actor, bool visible);
  size_t actor_count() const { return actors_.size(); }
  // Must be called after adding or moving actors and before casting.
  void commit();

  // Nearest hit of a ray with unit direction within [tnear, tfar]; thread-safe between commits.
  bool intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float tnear, float tfar,
                 RayHit& hit) const;

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
    Eigen::Matrix3f rotation;  // for bringing object-space normals to the world
    bool visible;
  };
  Prototype make_prototype(const TriangleMesh& mesh) const;

  RTCDevice device_ = nullptr;
  RTCScene top_ = nullptr;
  std::vector<Prototype> prototypes_;   // [0] is the static world
  std::vector<Actor> instances_;        // [0] is the static world's instance
  std::vector<int> actors_;             // actor id -> index into instances_
  std::vector<int> instance_of_geom_;   // top-level geomID -> index into instances_
  size_t world_triangles_ = 0;
};

}  // namespace lidarloop
