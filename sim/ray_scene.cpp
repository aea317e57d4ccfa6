#include "sim/ray_scene.hpp"

#include <limits>
#include <stdexcept>
#include <string>

namespace lidarloop {

static void check_device(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree error ") + std::to_string(err) + " in " + what);
}

RayScene::RayScene(const TriangleMesh& world, int threads) {
  const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
  device_ = rtcNewDevice(config.c_str());
  if (!device_) throw std::runtime_error("cannot create an Embree device");
  top_ = rtcNewScene(device_);
  world_triangles_ = world.triangle_count();
  prototypes_.push_back(make_prototype(world));
  add_actor(0, Eigen::Isometry3d::Identity());
  actors_.clear();  // the world's instance is not an actor
  commit();
}

RayScene::~RayScene() {
  for (auto& inst : instances_) rtcReleaseGeometry(inst.instance);
  for (auto& p : prototypes_) rtcReleaseScene(p.scene);
  rtcReleaseScene(top_);
  rtcReleaseDevice(device_);
}

RayScene::Prototype RayScene::make_prototype(const TriangleMesh& mesh) const {
  RTCScene scene = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.vertices[i][k];
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  check_device(device_, "building a mesh BVH");
  return {scene, mesh.materials};
}

int RayScene::add_prototype(const TriangleMesh& mesh) {
  prototypes_.push_back(make_prototype(mesh));
  return static_cast<int>(prototypes_.size()) - 1;
}

int RayScene::add_actor(int prototype, const Eigen::Isometry3d& pose) {
  if (prototype < 0 || prototype >= int(prototypes_.size())) throw std::out_of_range("unknown actor prototype");
  RTCGeometry inst = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(inst, prototypes_[prototype].scene);
  const unsigned geom_id = rtcAttachGeometry(top_, inst);
  instances_.push_back({prototype, inst, geom_id, Eigen::Matrix3f::Identity(), true});
  if (instance_of_geom_.size() <= geom_id) instance_of_geom_.resize(geom_id + 1, -1);
  instance_of_geom_[geom_id] = int(instances_.size()) - 1;
  actors_.push_back(int(instances_.size()) - 1);
  set_actor_pose(int(actors_.size()) - 1, pose);
  return int(actors_.size()) - 1;
}

void RayScene::set_actor_pose(int actor, const Eigen::Isometry3d& pose) {
  Actor& a = instances_.at(actors_.at(actor));
  const Eigen::Matrix<float, 3, 4> m = pose.matrix().topRows<3>().cast<float>();
  rtcSetGeometryTransform(a.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m.data());
  a.rotation = m.leftCols<3>();
  rtcCommitGeometry(a.instance);
}

void RayScene::set_actor_visible(int actor, bool visible) {
  Actor& a = instances_.at(actors_.at(actor));
  if (a.visible == visible) return;
  a.visible = visible;
  if (visible) rtcEnableGeometry(a.instance);
  else rtcDisableGeometry(a.instance);
}

void RayScene::commit() {
  rtcCommitScene(top_);
  check_device(device_, "committing the scene");
}

bool RayScene::intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float tnear, float tfar,
                         RayHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = origin.x(), rh.ray.org_y = origin.y(), rh.ray.org_z = origin.z();
  rh.ray.dir_x = direction.x(), rh.ray.dir_y = direction.y(), rh.ray.dir_z = direction.z();
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0;
  rh.ray.mask = std::numeric_limits<unsigned>::max();
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(top_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const Actor& inst = instances_[instance_of_geom_[rh.hit.instID[0]]];
  hit.range = rh.ray.tfar;
  hit.normal = (inst.rotation * Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)).normalized();
  hit.material = prototypes_[inst.prototype].materials[rh.hit.primID];
  return true;
}

}  // namespace lidarloop
