#pragma once
// /localizer/status: the localizer's own word on each of its estimates, as the standard
// diagnostic_msgs/msg/DiagnosticArray (what ROS 2's rqt_robot_monitor and Foxglove's diagnostics panel
// show) holding one DiagnosticStatus:
//   level        OK healthy, WARN degraded, ERROR lost, STALE not initialised (no pose yet)
//   name         "lidarloop localizer", hardware_id "lidarloop"
//   message      the health in words ("ok", "no GPS, few curbs", "lost")
//   values       health_flags               the health bits in hex ("0x4000"; localizer/localizer.hpp)
//                lost                       true | false
//                protection_lateral_m       the per-scan protection bounds (m, estimate's vehicle frame),
//                protection_longitudinal_m  shortest round-trip decimal, "inf" while lost
//                wide_search                true | false: the scan ran (a share of) a relocalization
//                mount_yaw_deg              only from a localizer that learns the LiDAR's mount yaw: its
//                mount_yaw_sigma_deg        estimate against the nominal mount and its 1 sigma (deg)
// header.stamp is the estimate's: the stamp of its /localizer/odometry, which is published only once
// the localizer has a pose, while the status goes out for every scan. header.frame_id is
// base_link_estimate, the frame the bounds are in.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "logs/ros2_messages.hpp"

namespace lidarloop {

inline constexpr const char* kLocalizerStatusName = "lidarloop localizer";

struct LocalizerStatus {
  int64_t stamp_ns = 0;
  uint8_t level = ros2::kDiagnosticOk;
  std::string health;  // in words
  uint32_t health_flags = 0;
  bool lost = false;
  double protection_lateral_m = std::numeric_limits<double>::infinity();
  double protection_longitudinal_m = std::numeric_limits<double>::infinity();
  bool wide_search = false;
  std::optional<double> mount_yaw_deg, mount_yaw_sigma_deg;  // both or neither
};

ros2::Bytes encode_localizer_status(const LocalizerStatus& status);
// The status named kLocalizerStatusName in a DiagnosticArray; nullopt when it holds none (another
// component's diagnostics). InputError naming `context` for a value missing or not of its form.
std::optional<LocalizerStatus> decode_localizer_status(ros2::View cdr, const std::string& context);

}  // namespace lidarloop
