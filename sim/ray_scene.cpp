#include "sim/ray_scene.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/input_error.hpp"

namespace lidarloop {

static void check_device(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error ") + std::to_string(err) + " in " + what);
}

// Embree picks its kernels by the processor it runs on (SSE4.2, AVX, AVX2, AVX-512), and they round
// differently: the same rays hit the same triangles at distances that differ in the last bits, and a
// closed loop fed those scans drifts apart (kidnap converged 1.6 s after the kidnap with one, 3.4 s with
// another). So the kernels are pinned (Embree 3 API, rtcNewDevice: the `isa` configuration), and every
// machine with the same ones casts the same scans: a scenario's log is the same bytes on a laptop, a
// cluster node and CI. AVX2 with FMA is on most x86 processors made since 2015 (not some Pentium,
// Celeron and Atom parts), and its 8-wide kernels cast a campus scan about 1.3 times as fast as
// SSE4.2's (`lidarloop bench lidar` times both). glibc's libm picks its FMA variants on the same
// processors, so the rest of the simulation agrees too. An older processor falls back to SSE4.2, and
// its scans differ in the last bits.
namespace {
constexpr const char* kIsaVariable = "LIDARLOOP_RAY_ISA";

bool cpu_has(const std::string& isa) {
#if defined(__x86_64__) || defined(__i386__)
  if (isa == kRayIsaSse42) return __builtin_cpu_supports("sse4.2");
  if (isa == kRayIsaAvx2) return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  // Embree's AVX-512 kernels are its Skylake-X ones.
  if (isa == kRayIsaAvx512)
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512vl");
#endif
  return isa == kRayIsaNative;
}

// InputError unless `isa` names kernels this processor runs; `who` names where the name came from.
void check_isa(const std::string& isa, const std::string& who) {
  if (isa != kRayIsaSse42 && isa != kRayIsaAvx2 && isa != kRayIsaAvx512 && isa != kRayIsaNative)
    throw InputError(who + isa + ": not one of " + kRayIsaSse42 + ", " + kRayIsaAvx2 + ", " + kRayIsaAvx512 + ", " +
                     kRayIsaNative);
  if (!cpu_has(isa)) throw InputError(who + isa + ": this processor does not have it");
}
}  // namespace

std::string ray_isa() {
  if (const char* env = std::getenv(kIsaVariable); env && *env) {
    check_isa(env, std::string(kIsaVariable) + "=");
    return env;
  }
#if defined(__x86_64__) || defined(__i386__)
  return cpu_has(kRayIsaAvx2) ? kRayIsaAvx2 : kRayIsaSse42;
#else
  return kRayIsaNative;
#endif
}

RayScene::RayScene(const TriangleMesh& world, int threads, MeshBuffers buffers, const std::string& isa) {
  check_isa(isa, "RayScene: kernels ");
  std::string config = isa == kRayIsaNative ? "" : "isa=" + isa;
  if (threads > 0) config += std::string(config.empty() ? "" : ",") + "threads=" + std::to_string(threads);
  device_ = rtcNewDevice(config.c_str());
  if (!device_) throw std::runtime_error("cannot create an Embree device");
  top_ = rtcNewScene(device_);
  world_triangles_ = world.triangle_count();
  prototypes_.push_back(make_prototype(world, buffers));
  add_actor(0, Eigen::Isometry3d::Identity());
  actors_.clear();  // the world's instance is not an actor
  instances_.front().actor = -1;
  commit();
}

RayScene::~RayScene() {
  for (auto& inst : instances_) rtcReleaseGeometry(inst.instance);
  for (auto& p : prototypes_) rtcReleaseScene(p.scene);
  rtcReleaseScene(top_);
  rtcReleaseDevice(device_);
}

namespace {

static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(std::array<uint32_t, 3>) == 3 * sizeof(unsigned),
              "shared buffers: a vertex is three packed floats, a triangle three packed indices");

void copy_buffers(RTCGeometry geom, const TriangleMesh& mesh) {
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.vertices[i][k];
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
}

// The same arrays, read where they are: the bytes Embree gets are the copy's bytes.
void share_buffers(RTCGeometry geom, const TriangleMesh& mesh) {
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.vertices.data(), 0,
                             sizeof(Eigen::Vector3f), mesh.vertices.size());
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                             sizeof(std::array<uint32_t, 3>), mesh.triangles.size());
}

}  // namespace

RayScene::Prototype RayScene::make_prototype(const TriangleMesh& mesh, MeshBuffers buffers) const {
  RTCScene scene = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  const bool padded = mesh.vertices.capacity() > mesh.vertices.size();
  if (buffers == MeshBuffers::shared && padded)
    share_buffers(geom, mesh);
  else
    copy_buffers(geom, mesh);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  check_device(device_, "building a mesh BVH");
  return {scene, mesh.materials};
}

int RayScene::add_prototype(const TriangleMesh& mesh) {
  prototypes_.push_back(make_prototype(mesh, MeshBuffers::copied));
  return static_cast<int>(prototypes_.size()) - 1;
}

int RayScene::add_actor(int prototype, const Eigen::Isometry3d& pose) {
  if (prototype < 0 || prototype >= int(prototypes_.size())) throw std::out_of_range("unknown actor prototype");
  RTCGeometry inst = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(inst, prototypes_[prototype].scene);
  const unsigned geom_id = rtcAttachGeometry(top_, inst);
  instances_.push_back({prototype, inst, geom_id, {}, true, int(actors_.size())});
  if (instance_of_geom_.size() <= geom_id) instance_of_geom_.resize(geom_id + 1, -1);
  instance_of_geom_[geom_id] = int(instances_.size()) - 1;
  actors_.push_back(int(instances_.size()) - 1);
  set_actor_pose(int(actors_.size()) - 1, pose);
  return int(actors_.size()) - 1;
}

void RayScene::set_actor_pose(int actor, const Eigen::Isometry3d& pose) { set_actor_motion(actor, {pose}); }

void RayScene::set_actor_motion(int actor, const std::vector<Eigen::Isometry3d>& keyframes) {
  if (keyframes.empty() || keyframes.size() > size_t(kMaxKeyframes))
    throw std::invalid_argument("set_actor_motion: 1 to " + std::to_string(kMaxKeyframes) + " keyframes");
  Actor& a = instances_.at(actors_.at(actor));
  rtcSetGeometryTimeStepCount(a.instance, unsigned(keyframes.size()));
  a.rotations.clear();
  for (size_t k = 0; k < keyframes.size(); ++k) {
    const Eigen::Matrix<float, 3, 4> m = keyframes[k].matrix().topRows<3>().cast<float>();
    rtcSetGeometryTransform(a.instance, unsigned(k), RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m.data());
    a.rotations.push_back(m.leftCols<3>());
  }
  rtcCommitGeometry(a.instance);
}

void RayScene::set_actor_visible(int actor, bool visible) {
  Actor& a = instances_.at(actors_.at(actor));
  if (a.visible == visible) return;
  a.visible = visible;
  if (visible)
    rtcEnableGeometry(a.instance);
  else
    rtcDisableGeometry(a.instance);
}

void RayScene::commit() {
  rtcCommitScene(top_);
  check_device(device_, "committing the scene");
}

RayHit RayScene::make_hit(unsigned inst_id, unsigned prim_id, float tfar, const Eigen::Vector3f& ng, float time) const {
  const Actor& inst = instances_[instance_of_geom_[inst_id]];
  // Embree reports instanced normals in the instance's object space; the nearest keyframe's
  // rotation is close enough for an incidence angle.
  const size_t k = size_t(std::lround(time * float(inst.rotations.size() - 1)));
  return {tfar, (inst.rotations[k] * ng).normalized(), prototypes_[inst.prototype].materials[prim_id], inst.actor};
}

bool RayScene::intersect(const Ray& ray, float tnear, float tfar, RayHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x(), rh.ray.org_y = ray.origin.y(), rh.ray.org_z = ray.origin.z();
  rh.ray.dir_x = ray.direction.x(), rh.ray.dir_y = ray.direction.y(), rh.ray.dir_z = ray.direction.z();
  rh.ray.tnear = tnear, rh.ray.tfar = tfar, rh.ray.time = ray.time;
  rh.ray.mask = std::numeric_limits<unsigned>::max(), rh.ray.id = 0, rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(top_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit = make_hit(rh.hit.instID[0], rh.hit.primID, rh.ray.tfar, {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, ray.time);
  return true;
}

bool RayScene::world_occludes(const Ray& ray, float tnear, float tfar) const {
  // The world's instance has the identity transform, so its own BVH is the world alone.
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  r.org_x = ray.origin.x(), r.org_y = ray.origin.y(), r.org_z = ray.origin.z();
  r.dir_x = ray.direction.x(), r.dir_y = ray.direction.y(), r.dir_z = ray.direction.z();
  r.tnear = tnear, r.tfar = tfar, r.time = 0;
  r.mask = std::numeric_limits<unsigned>::max(), r.id = 0, r.flags = 0;
  rtcOccluded1(prototypes_.front().scene, &context, &r);
  return r.tfar < 0;  // Embree marks an occluded ray with tfar = -inf
}

void RayScene::intersect8(const Ray* rays, int count, float tnear, float tfar, RayHit* hits, bool* found) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) int valid[kPacket];
  alignas(64) RTCRayHit16 rh;
  for (int k = 0; k < kPacket; ++k) {
    const Ray& r = rays[k < count ? k : 0];
    valid[k] = k < count ? -1 : 0;
    rh.ray.org_x[k] = r.origin.x(), rh.ray.org_y[k] = r.origin.y(), rh.ray.org_z[k] = r.origin.z();
    rh.ray.dir_x[k] = r.direction.x(), rh.ray.dir_y[k] = r.direction.y(), rh.ray.dir_z[k] = r.direction.z();
    rh.ray.tnear[k] = tnear, rh.ray.tfar[k] = tfar, rh.ray.time[k] = r.time;
    rh.ray.mask[k] = std::numeric_limits<unsigned>::max(), rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect16(valid, top_, &context, &rh);
  for (int k = 0; k < count; ++k) {
    found[k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
    if (found[k])
      hits[k] = make_hit(rh.hit.instID[0][k], rh.hit.primID[k], rh.ray.tfar[k],
                         {rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]}, rays[k].time);
  }
}

}  // namespace lidarloop
