#include "tools/run_recording.hpp"

#include "common/input_error.hpp"
#include "tools/map_cache.hpp"

namespace lidarloop {

std::unique_ptr<McapRecorder> start_recording(const std::optional<std::string>& path, const Scenario& scenario,
                                              const std::string& method) {
  if (!path) return nullptr;
  if (path->empty()) throw InputError("--record: needs a file name");
  auto recorder = std::make_unique<McapRecorder>(*path, scenario.lidar.mount());
  recorder->add_attachment(kScenarioAttachment, "application/yaml", scenario.text);
  recorder->add_metadata(kRunMetadata, {{"scenario", scenario.file},
                                        {"world", scenario.world},
                                        {"seed", std::to_string(scenario.seed)},
                                        {"duration_s", std::to_string(scenario.duration_s)},
                                        {"method", method},
                                        {"loop", scenario.closed_loop ? "closed" : "open"},
                                        {"map_hash", map_hash(scenario.world, MappingOptions{})},
                                        {"version", LIDARLOOP_VERSION}});
  return recorder;
}

}  // namespace lidarloop
