#include "external/external_localizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"

namespace lidarloop {
namespace {

using Clock = ChildProcess::Clock;

std::string exact(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// The stream as a program reading it live needs it: every message a record of its own, at once.
McapWriterOptions stream_options() {
  McapWriterOptions o;
  o.compress = false;
  o.chunked = false;
  o.background = false;
  return o;
}

std::string quoted_excerpt(const std::string& text) {
  constexpr size_t kShown = 80;
  std::string shown = text.substr(0, kShown);
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return "'" + shown + (text.size() > kShown ? "...'" : "'");
}

int64_t scan_end_ns(const PointCloud& cloud) { return cloud.stamp_ns + scan_duration_ns(cloud); }

double finite_number(const nlohmann::json& answer, const char* key, const std::string& where) {
  const auto& v = answer.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    throw InputError(where + ": \"" + key + "\" is not a finite number");
  return v.get<double>();
}

// The keys an answer may hold; anything else is refused, so a misspelled key is found at once.
const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = {"scan",     "x",          "y",    "yaw",
                                                "stamp_ns", "covariance", "lost", "protection"};
  return keys;
}

std::string listed(const std::vector<std::string>& keys) {
  std::string out;
  for (const auto& k : keys) out += (out.empty() ? "" : ", ") + k;
  return out;
}

// "lost": the program's own word that its pose is not to be trusted (LocalizerEstimate::lost).
bool lost_flag(const nlohmann::json& answer, const std::string& where) {
  if (!answer.contains("lost")) return false;
  const auto& v = answer["lost"];
  if (!v.is_boolean()) throw InputError(where + ": \"lost\" is not true or false");
  return v.get<bool>();
}

// "protection": [lateral_m, longitudinal_m], the error the program says its pose stays within, in its
// own vehicle frame, as the built-in localizer's protection bounds. NaN, none given, without it.
std::pair<double, double> protection_bounds(const nlohmann::json& answer, const std::string& where) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  if (!answer.contains("protection")) return {kNone, kNone};
  const auto& v = answer["protection"];
  const std::string expected = ": \"protection\" is not [lateral_m, longitudinal_m], two non-negative numbers";
  if (!v.is_array() || v.size() != 2) throw InputError(where + expected);
  for (const auto& bound : v)
    if (!bound.is_number() || !std::isfinite(bound.get<double>()) || bound.get<double>() < 0)
      throw InputError(where + expected);
  return {v[0].get<double>(), v[1].get<double>()};
}

}  // namespace

std::map<std::string, std::string> external_metadata(const HdMap& map, const LocalizerParams& params) {
  const Geodetic& origin = map.curbs.map().origin;
  const VehicleModelParams& v = params.vehicle;
  return {{"protocol_version", std::to_string(kExternalProtocolVersion)},
          {"world", map.intensity.header().world},
          {"map_origin_lat_deg", exact(origin.lat_deg)},
          {"map_origin_lon_deg", exact(origin.lon_deg)},
          {"map_origin_alt_m", exact(origin.alt_m)},
          {"map_projection", "transverse_mercator"},
          {"deadline_ms", exact(params.external.deadline_ms)},
          {"startup_timeout_s", exact(params.external.startup_timeout_s)},
          {"vehicle_lf_m", exact(v.lf)},
          {"vehicle_lr_m", exact(v.lr)},
          {"vehicle_steering_ratio", exact(v.steering_ratio)},
          // The rest of Eq. 19's parameters, so that a program can predict as the built-in localizer does.
          {"vehicle_mass_kg", exact(v.mass)},
          {"vehicle_yaw_inertia_kg_m2", exact(v.yaw_inertia)},
          {"vehicle_cornering_stiffness_front_n_per_rad", exact(v.cornering_stiffness_front)},
          {"vehicle_cornering_stiffness_rear_n_per_rad", exact(v.cornering_stiffness_rear)},
          {"vehicle_kinematic_below_mps", exact(v.kinematic_below)},
          {"gps_antenna_x_m", exact(params.gps_antenna.x())},
          {"gps_antenna_y_m", exact(params.gps_antenna.y())},
          {"gps_antenna_z_m", exact(params.gps_antenna.z())}};
}

ExternalLocalizer::ExternalLocalizer(const LocalizerParams& params, const std::map<std::string, std::string>& metadata)
    : params_(params),
      label_(method_label(params)),
      child_(params.external.command),
      recorder_(
          label_ + " stdin", [this](std::span<const uint8_t> bytes) { child_.send(bytes); }, params.lidar_mount,
          params.gps_antenna, stream_options(), kExternalMetadata, metadata) {
  recorder_.flush();
}

void ExternalLocalizer::fail(const std::string& problem, const PointCloud* cloud) {
  std::string where = "method " + label_;
  if (cloud) {
    char at[96];
    std::snprintf(at, sizeof at, ", scan %d (t = %.3f s)", scans_, double(scan_end_ns(*cloud)) / kNsPerS);
    where += at;
  }
  child_.kill();
  throw InputError(where + ": " + problem);
}

void ExternalLocalizer::on_can(const CanFrame& frame) { recorder_.write_can(frame); }

void ExternalLocalizer::on_gps(const GpsFix& fix) { recorder_.write_gps(fix); }

LocalizerEstimate ExternalLocalizer::on_scan(const PointCloud& cloud) {
  recorder_.write_scan(cloud);
  recorder_.flush();                // queued: the bytes go out while we wait for the answer
  const auto start = Clock::now();  // the program's latency, not our serialising
  const bool first = scans_ == 0;
  const auto allowed = first ? std::chrono::duration<double>(params_.external.startup_timeout_s)
                             : std::chrono::duration<double>(params_.external.deadline_ms / 1000.0);
  const auto deadline = start + std::chrono::duration_cast<Clock::duration>(allowed);
  std::string line;
  const ChildProcess::LineStatus status = child_.read_line(deadline, line);
  const double waited_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  switch (status) {
    case ChildProcess::LineStatus::line:
      break;
    case ChildProcess::LineStatus::timed_out: {
      // The usual cause is not a slow program but an answer that sits in its stdout buffer: a pipe is
      // not a terminal, so Python, C's stdio and Node's streams buffer it until the buffer fills.
      const std::string pending = child_.unread_output().empty()
                                      ? ""
                                      : " (it wrote " + quoted_excerpt(child_.unread_output()) + " without a newline)";
      char text[160];
      if (first)
        std::snprintf(text, sizeof text,
                      "no answer within the startup timeout (%.1f s, localizer.external.startup_timeout_s)",
                      params_.external.startup_timeout_s);
      else
        std::snprintf(text, sizeof text, "no answer within the %.0f ms deadline (localizer.external.deadline_ms)",
                      params_.external.deadline_ms);
      fail(std::string(text) + pending +
               ": does the program flush stdout after each answer? (Python: print(..., flush=True); C: "
               "fflush(stdout); a pipe is not a terminal, so the output is buffered)" +
               (first ? "; raise the timeout only if its start-up is slow" : ""),
           &cloud);
    }
    case ChildProcess::LineStatus::too_long:
      fail("answer longer than 64 KiB: " + quoted_excerpt(child_.unread_output()), &cloud);
    case ChildProcess::LineStatus::closed:
    case ChildProcess::LineStatus::stdin_closed: {
      const auto exit = child_.wait_exit(Clock::now() + std::chrono::milliseconds(500));
      std::string how = exit ? "the program " + describe_wait_status(*exit) : "the program closed its stdout";
      if (status == ChildProcess::LineStatus::stdin_closed) how += " (it stopped reading its input)";
      if (!child_.unread_output().empty()) how += "; it had written " + quoted_excerpt(child_.unread_output());
      fail(how + " before answering", &cloud);
    }
  }
  LocalizerEstimate e = parse_answer(line, cloud);
  e.total_ms = waited_ms;
  ++scans_;
  return e;
}

LocalizerEstimate ExternalLocalizer::parse_answer(const std::string& line, const PointCloud& cloud) {
  nlohmann::json answer;
  try {
    answer = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception&) {
    fail("answer is not JSON: " + quoted_excerpt(line) +
             ": stdout carries the answers only, one JSON object per line; write logs to stderr",
         &cloud);
  }
  if (!answer.is_object()) fail("answer is not a JSON object: " + quoted_excerpt(line), &cloud);
  const std::string where = "answer " + quoted_excerpt(line);
  try {
    const std::vector<std::string>& known = known_keys();
    for (const auto& [key, value] : answer.items())
      if (std::find(known.begin(), known.end(), key) == known.end())
        throw InputError(where + ": unknown key \"" + key + "\" (known: " + listed(known) + ")");
    if (!answer.contains("scan") || !answer["scan"].is_number_integer())
      throw InputError(where + ": no integer \"scan\"");
    if (answer["scan"].get<int64_t>() != scans_)
      throw InputError(where + ": is for scan " + std::to_string(answer["scan"].get<int64_t>()) + ", expected " +
                       std::to_string(scans_) + " (one answer per scan, in order)");
    LocalizerEstimate e;
    e.stamp_ns = scan_end_ns(cloud);
    e.points = cloud.points.size();
    const int pose_fields = int(answer.contains("x")) + int(answer.contains("y")) + int(answer.contains("yaw"));
    if (pose_fields != 0 && pose_fields != 3) throw InputError(where + ": give all of x, y and yaw, or none");
    if (pose_fields == 0) {
      // A scan without a pose is not scored, so a lost flag or bounds on it would be dropped unseen.
      if (answer.contains("lost") || answer.contains("protection"))
        throw InputError(where +
                         ": \"lost\" and \"protection\" describe a pose: give x, y and yaw with them (a "
                         "lost localizer answers the pose it holds, with \"lost\": true)");
      e.health = kNotInitialized;  // "no estimate": not scored, not steered on
      return e;
    }
    // Lost, it is scored as a built-in localizer's lost frame: its error counts, but it is never
    // misleading nor available, it is left out of NEES, and it marks when `lost` was raised and cleared.
    e.health = lost_flag(answer, where) ? uint32_t(kLost) : 0u;
    // Bounds not given stay NaN, not "anywhere" (infinity): the scorer does not count such a frame as
    // bounded, so a program that gives none is reported as giving none.
    std::tie(e.protection_lateral_m, e.protection_longitudinal_m) = protection_bounds(answer, where);
    e.pose = {finite_number(answer, "x", where), finite_number(answer, "y", where),
              wrap_angle(finite_number(answer, "yaw", where))};
    if (answer.contains("stamp_ns")) {
      if (!answer["stamp_ns"].is_number_integer()) throw InputError(where + ": \"stamp_ns\" is not an integer");
      e.stamp_ns = answer["stamp_ns"].get<int64_t>();
    }
    e.covariance = Eigen::Matrix3d::Zero();  // unknown unless given
    if (answer.contains("covariance")) {
      const auto& c = answer["covariance"];
      if (!c.is_array() || c.size() != 9) throw InputError(where + ": \"covariance\" is not an array of 9 numbers");
      for (int i = 0; i < 9; ++i) {
        if (!c[i].is_number() || !std::isfinite(c[i].get<double>()))
          throw InputError(where + ": \"covariance\" has a value that is not a finite number");
        e.covariance(i / 3, i % 3) = c[i].get<double>();
      }
      if ((e.covariance.diagonal().array() < 0).any())
        throw InputError(where + ": \"covariance\" has a negative variance");
    }
    return e;
  } catch (const InputError& error) {
    fail(error.what(), &cloud);
  } catch (const nlohmann::json::exception& error) {
    fail(where + ": " + error.what(), &cloud);
  }
}

void ExternalLocalizer::finish() {
  recorder_.close();  // Data End and the footer
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(params_.external.exit_timeout_s));
  child_.close_stdin(deadline);
  const auto exit = child_.wait_exit(deadline);
  if (!exit) {
    char text[96];
    std::snprintf(text, sizeof text, "did not exit within %.1f s of the end of its input (killed)",
                  params_.external.exit_timeout_s);
    fail(text);
  }
  if (*exit != 0) fail("the program " + describe_wait_status(*exit) + " at the end of its input");
  std::string rest;
  if (child_.read_line(Clock::now(), rest) == ChildProcess::LineStatus::line || !child_.unread_output().empty())
    fail("wrote more than one answer per scan: " + quoted_excerpt(rest.empty() ? child_.unread_output() : rest));
}

}  // namespace lidarloop
