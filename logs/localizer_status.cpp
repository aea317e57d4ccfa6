#include "logs/localizer_status.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string_view>

#include "common/input_error.hpp"
#include "logs/log_topics.hpp"
#include "logs/tum_file.hpp"

namespace lidarloop {
namespace {

constexpr const char* kHardwareId = "lidarloop";
constexpr int kHexBase = 16;

std::string word(bool b) { return b ? "true" : "false"; }

std::string hex(uint32_t flags) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%x", unsigned(flags));
  return text;
}

// The status's values by key; every one of them must be there.
class Values {
 public:
  Values(const ros2::DiagnosticStatus& status, std::string context) : context_(std::move(context)) {
    for (const auto& [key, value] : status.values) values_[key] = value;
  }
  const std::string& text(const std::string& key) const {
    const auto it = values_.find(key);
    if (it == values_.end()) throw InputError(context_ + ": the localizer status has no value '" + key + "'");
    return it->second;
  }
  bool boolean(const std::string& key) const {
    const std::string& v = text(key);
    if (v != "true" && v != "false") fail(key, v, "true or false");
    return v == "true";
  }
  double bound(const std::string& key) const {
    const std::string& v = text(key);
    double out = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
    // NaN passes (a bound not given); a negative one is no bound.
    if (ec != std::errc() || end != v.data() + v.size() || out < 0) fail(key, v, "a non-negative number or inf");
    return out;
  }
  bool has(const std::string& key) const { return values_.count(key) != 0; }
  // A finite number, at least `min`.
  double finite(const std::string& key, double min = -std::numeric_limits<double>::infinity()) const {
    const std::string& v = text(key);
    double out = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
    if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(out) || out < min)
      fail(key, v,
           min > -std::numeric_limits<double>::infinity() ? "a finite number, not negative" : "a finite number");
    return out;
  }
  uint32_t flags(const std::string& key) const {
    const std::string& v = text(key);
    const std::string_view prefix = "0x";
    if (v.size() <= prefix.size() || v.rfind(prefix, 0) != 0) fail(key, v, "a hexadecimal number (0x...)");
    uint32_t out = 0;
    const auto [end, ec] = std::from_chars(v.data() + prefix.size(), v.data() + v.size(), out, kHexBase);
    if (ec != std::errc() || end != v.data() + v.size()) fail(key, v, "a hexadecimal number (0x...)");
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& value, const std::string& expected) const {
    throw InputError(context_ + ": the localizer status's " + key + " is '" + value + "', expected " + expected);
  }
  std::map<std::string, std::string> values_;
  std::string context_;
};

}  // namespace

ros2::Bytes encode_localizer_status(const LocalizerStatus& s) {
  ros2::DiagnosticStatus d;
  d.level = s.level;
  d.name = kLocalizerStatusName;
  d.message = s.health;
  d.hardware_id = kHardwareId;
  d.values = {{"health_flags", hex(s.health_flags)},
              {"lost", word(s.lost)},
              {"protection_lateral_m", round_trip_number(s.protection_lateral_m)},
              {"protection_longitudinal_m", round_trip_number(s.protection_longitudinal_m)},
              {"wide_search", word(s.wide_search)}};
  if (s.mount_yaw_deg && s.mount_yaw_sigma_deg) {
    d.values.emplace_back("mount_yaw_deg", round_trip_number(*s.mount_yaw_deg));
    d.values.emplace_back("mount_yaw_sigma_deg", round_trip_number(*s.mount_yaw_sigma_deg));
  }
  return ros2::encode_diagnostic_array({s.stamp_ns, log_topics::estimate_frame, {d}});
}

std::optional<LocalizerStatus> decode_localizer_status(ros2::View cdr, const std::string& context) {
  const ros2::DiagnosticArray array = ros2::decode_diagnostic_array(cdr, context);
  for (const ros2::DiagnosticStatus& d : array.status) {
    if (d.name != kLocalizerStatusName) continue;
    if (d.level > ros2::kDiagnosticStale)
      throw InputError(context + ": the localizer status's level is " + std::to_string(d.level) + ", expected 0-3");
    const Values v(d, context);
    LocalizerStatus s;
    s.stamp_ns = array.stamp_ns;
    s.level = d.level;
    s.health = d.message;
    s.health_flags = v.flags("health_flags");
    s.lost = v.boolean("lost");
    s.protection_lateral_m = v.bound("protection_lateral_m");
    s.protection_longitudinal_m = v.bound("protection_longitudinal_m");
    s.wide_search = v.boolean("wide_search");
    if (v.has("mount_yaw_deg") || v.has("mount_yaw_sigma_deg")) {
      s.mount_yaw_deg = v.finite("mount_yaw_deg");
      s.mount_yaw_sigma_deg = v.finite("mount_yaw_sigma_deg", 0.0);
    }
    return s;
  }
  return std::nullopt;
}

}  // namespace lidarloop
