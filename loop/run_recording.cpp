#include "loop/run_recording.hpp"

#include "common/input_error.hpp"
#include "loop/localizer_setup.hpp"
#include "loop/map_cache.hpp"

namespace lidarloop {
namespace {
std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}
}  // namespace

void RecordingSink::on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) {
  std::vector<ros2::ActorState> states;
  states.reserve(actors.size());
  for (const auto& a : actors) states.push_back({a.name, actor_type_name(a.type), a.pose});
  log_.write_actors(stamp_ns, states);
}

std::unique_ptr<RecordingSink> start_recording(const std::optional<std::string>& path, const Scenario& scenario,
                                               const std::string& method, bool packets) {
  if (packets && !path) throw InputError("--packets: needs --record FILE.mcap");
  if (!path) return nullptr;
  if (path->empty()) throw InputError("--record: needs a file name");
  auto recorder = std::make_unique<RecordingSink>(*path, scenario.lidar.mount());
  recorder->record_packets(packets);
  McapRecorder& log = recorder->log();
  log.add_attachment(kScenarioAttachment, "application/yaml", scenario.text);
  log.add_metadata(kRunMetadata, {{"scenario", scenario.file},
                                  {"world", scenario.world},
                                  {"seed", std::to_string(scenario.seed)},
                                  {"duration_s", std::to_string(scenario.duration_s)},
                                  {"method", method},
                                  {"loop", scenario.closed_loop ? "closed" : "open"},
                                  {"map_hash", map_hash(scenario.world, scenario_mapping_options(scenario))},
                                  {"realism", realism_name(scenario.realism)},
                                  {"realism_overrides", join_lines(realism_overrides(scenario))},
                                  {"version", LIDARLOOP_VERSION}});
  return recorder;
}

}  // namespace lidarloop
