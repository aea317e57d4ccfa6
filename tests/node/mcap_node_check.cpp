// The C++ half of the Node.js cross-check (see read_mcap.mjs and node_test.cmake).
//   mcap_node_check write FILE.mcap           records the synthetic run through McapRecorder
//   mcap_node_check compare FILE.mcap OUT.json checks what the Node reader printed against what was
//                                              written: counts per topic, the first scan's stamp,
//                                              fields, and first and last points, value for value.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "../logs/mcap_fixture.hpp"
#include "common/input_error.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"

using namespace lidarloop;
using nlohmann::json;

namespace {

test::SyntheticRun the_run() { return test::make_synthetic_run(1.25, 2000, 42); }

int failures = 0;

template <class A, class B>
void expect_equal(const std::string& what, const A& got, const B& want) {
  if (got == want) return;
  ++failures;
  std::cerr << "mismatch: " << what << ": node read " << json(got).dump() << ", the writer wrote " << json(want).dump()
            << "\n";
}

void compare_point(const std::string& which, const json& got, const LidarPoint& want) {
  // JSON numbers are doubles: a float32 field round-trips exactly as the double of that float.
  expect_equal(which + ".x", got.at("x").get<double>(), double(want.x));
  expect_equal(which + ".y", got.at("y").get<double>(), double(want.y));
  expect_equal(which + ".z", got.at("z").get<double>(), double(want.z));
  expect_equal(which + ".intensity", got.at("intensity").get<double>(), double(want.intensity));
  expect_equal(which + ".ring", got.at("ring").get<int>(), int(want.ring));
  expect_equal(which + ".t_ns", got.at("t_ns").get<uint64_t>(), uint64_t(want.t_ns));
}

int compare(const std::string& mcap, const std::string& json_path) {
  std::ifstream in(json_path);
  const json node = json::parse(in);
  const test::SyntheticRun run = the_run();
  namespace t = log_topics;
  const std::map<std::string, size_t> written = {{t::tf_static, 1},
                                                 {t::vehicle_report, run.can.size()},
                                                 {t::truth_state, run.truth.size()},
                                                 {t::truth_body, run.truth.size()},
                                                 {t::truth_odometry, run.truth.size()},
                                                 {t::tf, run.truth.size() + run.estimates.size()},
                                                 {t::gps_fix, run.gps.size()},
                                                 {t::gps_heading, run.gps.size()},
                                                 {t::rtk_fix, run.rtk.size()},
                                                 {t::rtk_heading, run.rtk.size()},
                                                 {t::scan, run.scans.size()},
                                                 {t::truth_actors, run.actors.size()},
                                                 {t::estimate, run.estimates.size()},
                                                 {t::localizer_status, run.estimates.size()}};
  expect_equal("counts per topic", node.at("counts").get<std::map<std::string, size_t>>(), written);

  // And the C++ reader sees the same file the same way.
  std::map<std::string, size_t> ours;
  McapReader reader(mcap);
  for (McapMessage m; reader.next(m);) ++ours[m.channel->topic];
  expect_equal("counts per topic (C++ reader)", ours, written);
  expect_equal("profile", node.at("header").at("profile").get<std::string>(), reader.header().profile);
  expect_equal("library", node.at("header").at("library").get<std::string>(), reader.header().library);

  const json& scan = node.at("first_scan");
  const PointCloud& first = run.scans.at(0);
  expect_equal(
      "first scan stamp",
      scan.at("stamp").at("sec").get<int64_t>() * 1'000'000'000 + scan.at("stamp").at("nanosec").get<int64_t>(),
      first.stamp_ns);
  expect_equal("first scan frame", scan.at("frame_id").get<std::string>(), std::string(t::lidar_frame));
  expect_equal("first scan width", scan.at("width").get<size_t>(), first.points.size());
  expect_equal("first scan fields", scan.at("fields").get<std::vector<std::string>>(),
               std::vector<std::string>{"x", "y", "z", "intensity", "ring", "t_ns"});
  compare_point("first point", scan.at("first"), first.points.front());
  compare_point("last point", scan.at("last"), first.points.back());

  // The first lost status, as Foxglove's ROS 2 decoder reads the DiagnosticArray.
  const json& status = node.at("lost_status");
  const auto lost = std::find_if(run.estimates.begin(), run.estimates.end(),
                                 [](const test::SyntheticEstimate& e) { return e.status.lost; });
  if (lost == run.estimates.end() || status.is_null()) {
    expect_equal("a lost status", status.is_null(), lost == run.estimates.end());
  } else {
    expect_equal(
        "lost status stamp",
        status.at("stamp").at("sec").get<int64_t>() * 1'000'000'000 + status.at("stamp").at("nanosec").get<int64_t>(),
        lost->stamp_ns);
    expect_equal("lost status level", status.at("level").get<int>(), int(lost->status.level));
    expect_equal("lost status name", status.at("name").get<std::string>(), std::string(kLocalizerStatusName));
    expect_equal("lost status message", status.at("message").get<std::string>(), lost->status.health);
    expect_equal("lost status hardware_id", status.at("hardware_id").get<std::string>(), std::string("lidarloop"));
    expect_equal("lost status values", status.at("values").get<std::map<std::string, std::string>>(),
                 std::map<std::string, std::string>{{"health_flags", "0x4000"},
                                                    {"lost", "true"},
                                                    {"protection_lateral_m", "inf"},
                                                    {"protection_longitudinal_m", "inf"},
                                                    {"wide_search", "true"}});
  }

  expect_equal("attachments", node.at("attachments").size(), size_t(1));
  expect_equal("attachment name", node.at("attachments").at(0).at("name").get<std::string>(),
               std::string("scenario.yaml"));
  expect_equal("attachment size", node.at("attachments").at(0).at("size").get<size_t>(), run.scenario_yaml.size());
  expect_equal("metadata", node.at("metadata").at("run").at("seed").get<std::string>(), std::string("7"));

  if (failures == 0)
    std::cout << "the Node.js reader agrees with the writer: " << node.at("counts").size() << " topics, "
              << run.scans.size()
              << " scans, first and last points of the first scan, the first lost localizer status\n";
  return failures == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && argc == 3) {
      const McapWriterStats s = test::record_synthetic_run(the_run(), argv[2]);
      std::cout << "wrote " << argv[2] << ": " << s.messages << " messages in " << s.chunks << " chunks, "
                << s.file_bytes << " bytes\n";
      return 0;
    }
    if (mode == "compare" && argc == 4) return compare(argv[2], argv[3]);
    std::cerr << "usage: mcap_node_check write FILE.mcap | compare FILE.mcap NODE.json\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mcap_node_check: " << e.what() << "\n";
    return 1;
  }
}
