// The localizer's side of the `gicp` matcher: the target's bookkeeping here, Open3D's work in the
// module that gicp_backend.hpp describes, loaded on first use.
#include "localizer/gicp_matcher.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "localizer/gicp_backend.hpp"

namespace lidarloop {

namespace {

#ifdef LIDARLOOP_GICP_MODULE
constexpr const char* kModule = LIDARLOOP_GICP_MODULE;
#else
constexpr const char* kModule = nullptr;
#endif

// Loaded once, by the first thread to need it (a function-local static is initialised once); never
// unloaded, so the module's code stays valid for every target still alive.
const GicpBackend& backend() {
  static const GicpBackend* const loaded = [] {
    if (!kModule) throw std::runtime_error(kGicpUnavailable);
    void* module = dlopen(kModule, RTLD_NOW | RTLD_LOCAL);
    if (!module) throw std::runtime_error(std::string("gicp: cannot load the Open3D module: ") + dlerror());
    using Entry = const GicpBackend* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(module, "lidarloop_gicp_backend"));
    if (!entry) throw std::runtime_error(std::string("gicp: ") + kModule + " has no entry point");
    return entry();
  }();
  return *loaded;
}

}  // namespace

bool gicp_available() { return kModule != nullptr; }

struct GicpTarget::Cloud {
  GicpCloud* cloud;
  explicit Cloud(GicpCloud* c) : cloud(c) {}
  ~Cloud() { backend().destroy(cloud); }
  Cloud(const Cloud&) = delete;
  Cloud& operator=(const Cloud&) = delete;
};

const char* gicp_status_name(GicpStatus s) {
  switch (s) {
    case GicpStatus::ok:
      return "ok";
    case GicpStatus::few_scan_points:
      return "few scan points";
    case GicpStatus::few_map_points:
      return "few map points";
    case GicpStatus::not_converged:
      return "not converged";
    case GicpStatus::low_fitness:
      return "low fitness";
  }
  return "?";
}

GicpTarget::GicpTarget() = default;
GicpTarget::~GicpTarget() = default;
GicpTarget::GicpTarget(GicpTarget&&) noexcept = default;
GicpTarget& GicpTarget::operator=(GicpTarget&&) noexcept = default;

double GicpTarget::radius(const GicpParams& p) {
  return p.max_range_m + p.target_reuse_m + std::max(p.max_correspondence_m, p.max_correspondence_widened_m);
}

bool GicpTarget::covers(const Eigen::Vector2d& centre, const GicpParams& p) const {
  return cloud_ && centre_ && (centre - *centre_).norm() <= p.target_reuse_m;
}

void GicpTarget::build(const std::vector<Eigen::Vector3d>& map_points, const Eigen::Vector2d& centre,
                       const GicpParams& p) {
  const bool reuse = cloud_ && centre_;
  auto cloud =
      std::make_unique<Cloud>(backend().build(map_points, reuse ? cloud_->cloud : nullptr, reuse ? &*centre_ : nullptr,
                                              radius(p) - p.covariance_reuse_margin_m, p));
  cloud_ = std::move(cloud);
  centre_ = centre;
  ++builds_;
}

size_t GicpTarget::size() const { return cloud_ ? backend().size(cloud_->cloud) : 0; }

GicpResult gicp_match(const std::vector<Eigen::Vector3d>& scan, const Eigen::Isometry3d& prior,
                      const GicpTarget& target, const GicpParams& p, double max_correspondence_m) {
  return backend().match(scan, prior, target.cloud() ? target.cloud()->cloud : nullptr, p, max_correspondence_m);
}

}  // namespace lidarloop
