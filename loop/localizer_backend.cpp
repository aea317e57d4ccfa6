#include "loop/localizer_backend.hpp"

namespace lidarloop {

LocalizerBackend::LocalizerBackend(HdMap& map, const LocalizerParams& params, const Scenario& scenario)
    : label_(method_label(params)), kidnaps_(scenario) {
  check_kidnaps_supported(scenario, params);  // before an external program is started
  if (params.external.command.empty())
    builtin_ = std::make_unique<Localizer>(map, params);
  else
    external_ = std::make_unique<ExternalLocalizer>(params, external_metadata(map, params));
}

void LocalizerBackend::on_can(const CanFrame& frame) {
  if (builtin_)
    builtin_->on_can(frame);
  else
    external_->on_can(frame);
}

void LocalizerBackend::on_gps(const GpsFix& fix) {
  if (builtin_)
    builtin_->on_gps(fix);
  else
    external_->on_gps(fix);
}

LocalizerEstimate LocalizerBackend::on_scan(const PointCloud& cloud) {
  if (!builtin_) return external_->on_scan(cloud);
  for (const Pose2d& offset : kidnaps_.due(cloud.stamp_ns)) builtin_->displace(offset);
  return builtin_->on_scan(cloud);
}

const ScanFeatures& LocalizerBackend::last_features() const {
  return builtin_ ? builtin_->last_features() : no_features_;
}

void LocalizerBackend::finish() {
  if (external_) external_->finish();
}

}  // namespace lidarloop
