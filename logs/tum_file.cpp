#include "logs/tum_file.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "common/input_error.hpp"
#include "common/units.hpp"

namespace lidarloop {

namespace {

constexpr int kNsDigits = 9;
// A quaternion shorter than this has no direction to speak of (a line of zeros, a typo).
constexpr double kMinQuaternionNorm = 1e-6;

// A number as a whole token: the full text must be consumed (strtod alone accepts "1.5abc").
bool parse_double(const std::string& token, double& value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (!token.empty() && token.front() == '+') ++begin;  // from_chars does not take a leading '+'
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  return ec == std::errc() && ptr == end && std::isfinite(value);
}

}  // namespace

std::string tum_seconds(int64_t stamp_ns) {
  const char* sign = stamp_ns < 0 ? "-" : "";
  const uint64_t magnitude = stamp_ns < 0 ? uint64_t(0) - uint64_t(stamp_ns) : uint64_t(stamp_ns);
  char text[48];
  std::snprintf(text, sizeof text, "%s%llu.%09llu", sign, static_cast<unsigned long long>(magnitude / kNsPerS),
                static_cast<unsigned long long>(magnitude % kNsPerS));
  return text;
}

std::string round_trip_number(double value) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
  return std::string(text, ec == std::errc() ? end : text);
}

std::string tum_line(const TumPose& p) {
  const Eigen::Quaterniond& q = p.orientation;
  std::string line = tum_seconds(p.stamp_ns);
  for (double v : {p.position.x(), p.position.y(), p.position.z(), q.x(), q.y(), q.z(), q.w()})
    line += ' ' + round_trip_number(v + 0.0);  // + 0.0: no "-0"
  return line;
}

bool parse_tum_seconds(const std::string& text, int64_t& stamp_ns) {
  // Exact path: [-]digits[.digits], at most nine fractional digits.
  size_t i = 0;
  const bool negative = !text.empty() && text[0] == '-';
  if (negative || (!text.empty() && text[0] == '+')) i = 1;
  const size_t dot = text.find('.', i);
  const std::string whole = text.substr(i, dot == std::string::npos ? std::string::npos : dot - i);
  const std::string fraction = dot == std::string::npos ? "" : text.substr(dot + 1);
  auto digits = [](const std::string& s) { return s.find_first_not_of("0123456789") == std::string::npos; };
  if (!whole.empty() && whole.size() <= 10 && digits(whole) && digits(fraction) && fraction.size() <= kNsDigits) {
    int64_t ns = std::stoll(whole) * kNsPerS;
    if (!fraction.empty()) ns += std::stoll(fraction + std::string(kNsDigits - fraction.size(), '0'));
    stamp_ns = negative ? -ns : ns;
    return true;
  }
  double seconds = 0;
  constexpr double kMaxSeconds = 9e9;  // int64 nanoseconds hold 292 years; this is far inside
  if (!parse_double(text, seconds) || std::abs(seconds) > kMaxSeconds) return false;
  stamp_ns = std::llround(seconds * double(kNsPerS));
  return true;
}

std::vector<TumPose> parse_tum(const std::string& text, const std::string& file) {
  std::vector<TumPose> poses;
  std::istringstream in(text);
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // a file written on Windows
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = file + ":" + std::to_string(number) + ": ";
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string t; fields >> t;) tokens.push_back(t);
    if (tokens.size() != 8)
      throw InputError(where + "expected 8 numbers (t x y z qx qy qz qw), got " + std::to_string(tokens.size()));
    TumPose p;
    if (!parse_tum_seconds(tokens[0], p.stamp_ns))
      throw InputError(where + "time stamp '" + tokens[0] + "' is not a finite number of seconds");
    double v[7];
    for (int k = 0; k < 7; ++k)
      if (!parse_double(tokens[size_t(k) + 1], v[k]))
        throw InputError(where + "'" + tokens[size_t(k) + 1] + "' is not a finite number");
    p.position = {v[0], v[1], v[2]};
    p.orientation = Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
    if (!(p.orientation.norm() >= kMinQuaternionNorm)) throw InputError(where + "the quaternion is zero");
    if (!poses.empty() && p.stamp_ns <= poses.back().stamp_ns)
      throw InputError(where + "time stamp " + tum_seconds(p.stamp_ns) + " s is not after the previous line's " +
                       tum_seconds(poses.back().stamp_ns) + " s (stamps must increase)");
    poses.push_back(p);
  }
  if (poses.empty()) throw InputError(file + ": no poses (an empty TUM file)");
  return poses;
}

}  // namespace lidarloop
