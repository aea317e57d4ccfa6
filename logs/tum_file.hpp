#pragma once
// TUM trajectories ("t x y z qx qy qz qw" a line, t in seconds; evo's format), written and read back
// exactly: the stamp as integer nanoseconds ("sec.nnnnnnnnn", never through a double) and every
// other number in the shortest form that reads back as the same double. So a pose exported from a log
// and scored again is bit for bit the pose the log holds (`lidarloop score`'s round trip).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace lidarloop {

struct TumPose {
  int64_t stamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

inline constexpr const char* kTumHeader = "# timestamp x y z qx qy qz qw\n";

// "sec.nnnnnnnnn" exactly, with a sign for negative stamps.
std::string tum_seconds(int64_t stamp_ns);
// The shortest text that reads back as `value` ("1.25", "0.1", "-2.5e-07").
std::string round_trip_number(double value);
// One line, without the line break.
std::string tum_line(const TumPose& pose);

// Seconds as written in a TUM file to integer nanoseconds: a plain decimal with at most nine
// fractional digits is read exactly; anything else a number reads (more digits, an exponent) is
// rounded to the nearest nanosecond. False when `text` is not a finite number or out of range.
bool parse_tum_seconds(const std::string& text, int64_t& stamp_ns);

// Parses a TUM file's text. `file` names it in errors. Blank lines and lines starting with '#' are
// skipped. InputError "FILE:LINE: problem" for a line that is not eight finite numbers, a zero
// quaternion, or a stamp not after the previous line's; "FILE: no poses" for a file without any.
std::vector<TumPose> parse_tum(const std::string& text, const std::string& file);

}  // namespace lidarloop
