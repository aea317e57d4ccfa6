// A localizer whose integrity claims are known in advance, for the test that an exec: program's `lost`
// and protection bounds are scored exactly (tests/cli/external_integrity.cmake). It answers the last
// GPS fix's antenna position and heading as its pose (metres off the rear axle: never exactly the
// truth), for its first kEstimates scans that have a fix, then "no estimate". The k-th estimate claims,
// by k % 4:
//   0  protection [0, 0]            misleading (any error exceeds 0) and available (0 < alert limits)
//   1  protection [1e6, 1e6]        bounded, never misleading, never available
//   2  protection [0, 0], lost      bounded, never misleading (lost), never available
//   3  no protection                not bounded, never available
// So, every estimate scored: frames kEstimates, frames_with_bounds 3/4 of them, misleading 1/4,
// availability 1/4, and `lost` raised at the third estimate and cleared at the fourth.
#include <cstdio>
#include <map>
#include <optional>
#include <string>

#include "common/geodetic.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/ros2_messages.hpp"

namespace {

constexpr int kEstimates = 20;    // 2 s of scans at 10 Hz: within the test's 3 s scenario
constexpr int kClaims = 4;        // the cycle of claims above
constexpr double kNowhere = 1e6;  // m: a bound no error of the campus exceeds, yet over any alert limit

void print_claims(int k) {
  switch (k % kClaims) {
    case 0:
      std::printf(", \"protection\": [0, 0]");
      break;
    case 1:
      std::printf(", \"protection\": [%g, %g]", kNowhere, kNowhere);
      break;
    case 2:
      std::printf(", \"protection\": [0, 0], \"lost\": true");
      break;
    default:
      std::printf(", \"lost\": false");  // no bounds
  }
}

}  // namespace

int main() {
  using namespace lidarloop;
  McapReader reader(stdin, "stdin");
  std::optional<LocalFrame> frame;
  std::optional<Eigen::Vector2d> antenna;  // the last fix, in the map frame
  double heading = 0;
  int scan = 0, estimates = 0;
  for (McapMessage m; reader.next(m);) {
    if (!frame) {  // the metadata comes before the first message
      std::map<std::string, std::string> meta;
      for (const auto& record : reader.metadata())
        if (record.name == "lidarloop.external") meta.insert(record.metadata.begin(), record.metadata.end());
      frame.emplace(Geodetic{std::stod(meta.at("map_origin_lat_deg")), std::stod(meta.at("map_origin_lon_deg")),
                             std::stod(meta.at("map_origin_alt_m"))});
    }
    const std::string& topic = m.channel->topic;
    if (topic == log_topics::gps_fix) {
      const GpsFix fix = ros2::decode_nav_sat_fix(m.data, topic);
      if (fix.status != GpsStatus::no_fix) antenna = frame->to_local(fix.lat_deg, fix.lon_deg);
    } else if (topic == log_topics::gps_heading) {
      heading = ros2::decode_gnss_heading(m.data, topic).heading;
    } else if (topic == log_topics::scan) {
      if (antenna && estimates < kEstimates) {
        std::printf("{\"scan\": %d, \"x\": %.17g, \"y\": %.17g, \"yaw\": %.17g", scan, antenna->x(), antenna->y(),
                    heading);
        print_claims(estimates++);
        std::printf("}\n");
      } else {
        std::printf("{\"scan\": %d}\n", scan);
      }
      ++scan;
      std::fflush(stdout);
    }
  }
  return 0;
}
