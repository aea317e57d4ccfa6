#pragma once
// One localizer in the loop, whichever kind: a built-in method (localizer/localizer.hpp) or another
// program (`exec:`, external/external_localizer.hpp). The loop, replay and compare drive this.
#include <memory>
#include <string>

#include "external/external_localizer.hpp"
#include "localizer/localizer.hpp"
#include "loop/kidnap_schedule.hpp"

namespace lidarloop {

class LocalizerBackend {
 public:
  // `map` must outlive it. An external program is started here (InputError if it cannot be).
  // `scenario`: the run's; its kidnaps of the belief are done to the localizer before the scans they fall
  // due at (loop/kidnap_schedule.hpp), which needs a built-in method (InputError naming it otherwise).
  // A kidnap of the car is in the scans already.
  LocalizerBackend(HdMap& map, const LocalizerParams& params, const Scenario& scenario);

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
  KidnapSchedule kidnaps_;
  ScanFeatures no_features_;
};

}  // namespace lidarloop
