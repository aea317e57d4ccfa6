#pragma once
// One localizer in the loop, whichever kind: a built-in method (localizer/localizer.hpp) or another
// program (`exec:`, loop/external_localizer.hpp). The loop, replay and compare drive this.
#include <memory>
#include <string>

#include "localizer/localizer.hpp"
#include "loop/external_localizer.hpp"

namespace lidarloop {

class LocalizerBackend {
 public:
  // `map` must outlive it. An external program is started here (InputError if it cannot be).
  LocalizerBackend(HdMap& map, const LocalizerParams& params);

  void on_can(const CanFrame& frame);
  void on_gps(const GpsFix& fix);
  LocalizerEstimate on_scan(const PointCloud& cloud);
  // The last scan's features (none from an external program: it does not say).
  const ScanFeatures& last_features() const;
  // After the last message: an external program is told the stream ended and must exit cleanly.
  void finish();

  const std::string& label() const { return label_; }

 private:
  std::string label_;
  std::unique_ptr<Localizer> builtin_;
  std::unique_ptr<ExternalLocalizer> external_;
  ScanFeatures no_features_;
};

}  // namespace lidarloop
