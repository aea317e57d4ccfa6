#include "scoring/result_files.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/tum_file.hpp"

namespace lidarloop {

namespace {

using json = nlohmann::ordered_json;  // keys in the order written, for people reading the file

constexpr int kJsonIndent = 2;

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

// Full precision for machines; "nan" stays as it is (pandas and numpy read it).
std::string number(double value) { return format("%.9g", value); }

json finite_or_null(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }
json optional_or_null(const std::optional<double>& value) { return value ? json(*value) : json(nullptr); }

std::string xml_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        // XML 1.0 forbids most control characters even when escaped.
        out += (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') ? '?' : c;
    }
  }
  return out;
}

std::string joined(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? separator : "") + parts[i];
  return out;
}

// For people: fixed decimals, "n/a" where there is no value.
std::string cell(double value, const char* pattern) { return std::isfinite(value) ? format(pattern, value) : "n/a"; }

std::string summary(const Metrics& m) {
  std::string text = std::to_string(m.frames) + " frames; lateral RMSE " + format("%.3f", m.lateral_rmse_m) +
                     " m, longitudinal RMSE " + format("%.3f", m.longitudinal_rmse_m) + " m, heading RMSE " +
                     format("%.3f", m.heading_rmse_deg) + " deg, max position error " +
                     format("%.3f", m.max_position_error_m) + " m, latency p50 " + cell(m.latency_p50_ms, "%.2f ms") +
                     ", coverage " + cell(100 * m.coverage, "%.1f%%");
  text += "; " + consistency_text(m) + "; " + integrity_text(m);
  for (const EventRecovery& r : m.recovery) text += "; " + recovery_text(r);
  return text;
}

json recovery_json(const std::vector<EventRecovery>& events) {
  json out = json::array();
  for (const EventRecovery& r : events)
    out.push_back({{"event", r.event.what},
                   {"t_s", double(r.event.stamp_ns) / double(kNsPerS)},
                   {"converged_after_s", finite_or_null(r.converged_after_s)},
                   {"lost_raised_after_s", finite_or_null(r.lost_raised_after_s)},
                   {"lost_cleared_after_s", finite_or_null(r.lost_cleared_after_s)}});
  return out;
}

json reference_json(const std::optional<ReferenceAccuracy>& reference) {
  if (!reference) return nullptr;
  const ReferenceAccuracy& r = *reference;
  return {{"kind", reference_kind_name(r.config.kind)},
          {"sigma_xy_m", r.config.sigma_xy_m},
          {"heading_sigma_deg", r.config.heading_sigma_rad * kDegPerRad},
          {"correlation_s", r.config.correlation_s},
          {"lateral_rmse_m", finite_or_null(r.lateral_rmse_m)},
          {"longitudinal_rmse_m", finite_or_null(r.longitudinal_rmse_m)},
          {"heading_rmse_deg", finite_or_null(r.heading_rmse_deg)},
          {"position_rmse_m", finite_or_null(r.position_rmse_m)},
          {"max_position_error_m", finite_or_null(r.max_position_error_m)},
          {"max_lateral_m", finite_or_null(r.max_lateral_m)},
          {"max_longitudinal_m", finite_or_null(r.max_longitudinal_m)},
          {"max_heading_deg", finite_or_null(r.max_heading_deg)},
          {"reference_error",
           {{"lateral_rms_m", finite_or_null(r.error_lateral_rms_m)},
            {"longitudinal_rms_m", finite_or_null(r.error_longitudinal_rms_m)},
            {"heading_rms_deg", finite_or_null(r.error_heading_rms_deg)}}}};
}

std::string markdown_cell(std::string s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

}  // namespace

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string quoted = "\"";
  for (char c : s) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::optional<std::string> read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) return std::nullopt;
  return text.str();
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot open for writing");
  out << text;
  out.close();
  if (!out) throw InputError(path + ": cannot write");
}

json observations_json(const std::optional<ObservationConsistency>& o) {
  if (!o) return nullptr;
  const char* axes[] = {"along", "across", "heading"};
  json out;
  for (int axis = 0; axis < 3; ++axis)
    out[axes[axis]] = {{"observations", o->counts(axis)},
                       {"mean_nees", finite_or_null(o->mean_nees(axis))},
                       {"rms_error", finite_or_null(o->rms_error(axis))}};
  return out;
}

std::string metrics_json(const Metrics& m) {
  const json doc = {
      {"method", m.method},
      {"scenario", m.scenario},
      {"realism",
       {{"profile", m.realism},
        {"overrides", m.realism_overrides},
        {"lidar_mount_error",
         {{"rpy_deg", {m.mount_error_rpy_deg.x(), m.mount_error_rpy_deg.y(), m.mount_error_rpy_deg.z()}},
          {"xyz_m", {m.mount_error_xyz_m.x(), m.mount_error_xyz_m.y(), m.mount_error_xyz_m.z()}}}}}},
      {"frames", m.frames},
      {"unscored_frames", m.unscored_frames},
      {"settling_frames", m.settling_frames},
      {"lateral_rmse_m", finite_or_null(m.lateral_rmse_m)},
      {"longitudinal_rmse_m", finite_or_null(m.longitudinal_rmse_m)},
      {"heading_rmse_deg", finite_or_null(m.heading_rmse_deg)},
      {"position_rmse_m", finite_or_null(m.position_rmse_m)},
      {"max_position_error_m", finite_or_null(m.max_position_error_m)},
      {"max_lateral_m", finite_or_null(m.max_lateral_m)},
      {"max_longitudinal_m", finite_or_null(m.max_longitudinal_m)},
      {"max_heading_deg", finite_or_null(m.max_heading_deg)},
      {"worst_frame_t_s", double(m.worst_frame_stamp_ns) / double(kNsPerS)},
      {"reference", reference_json(m.reference)},
      {"latency_p50_ms", finite_or_null(m.latency_p50_ms)},
      {"latency_p99_ms", finite_or_null(m.latency_p99_ms)},
      {"latency_max_ms", finite_or_null(m.latency_max_ms)},
      {"latency_first_scan_ms", finite_or_null(m.latency_first_scan_ms)},
      {"coverage", finite_or_null(m.coverage)},
      {"largest_gap_s", finite_or_null(m.largest_gap_s)},
      {"max_lane_offset_m", finite_or_null(m.max_lane_offset_m)},
      {"curb_hidden_fraction", finite_or_null(m.curb_hidden_fraction)},
      {"curb_hidden_fraction_max", finite_or_null(m.curb_hidden_fraction_max)},
      {"recovery_frames", m.recovery_frames},
      {"consistency",
       {{"frames_with_covariance", m.consistency.frames},
        {"mean_nees_lateral", finite_or_null(m.consistency.mean_nees_lateral)},
        {"mean_nees_longitudinal", finite_or_null(m.consistency.mean_nees_longitudinal)},
        {"mean_nees_heading", finite_or_null(m.consistency.mean_nees_heading)},
        {"beyond_3_sigma_lateral", finite_or_null(m.consistency.beyond_3_sigma_lateral)},
        {"beyond_3_sigma_longitudinal", finite_or_null(m.consistency.beyond_3_sigma_longitudinal)},
        {"beyond_3_sigma_heading", finite_or_null(m.consistency.beyond_3_sigma_heading)},
        {"beyond_3_sigma_any", finite_or_null(m.consistency.beyond_3_sigma_any)}}},
      {"integrity",
       {{"frames_with_bounds", m.integrity.frames_with_bounds},
        {"misleading_frames", m.integrity.misleading_frames},
        {"misleading_fraction", finite_or_null(m.integrity.misleading_fraction)},
        {"frames_awaiting_alert", m.integrity.frames_awaiting_alert},
        {"misleading_awaiting_alert", m.integrity.misleading_awaiting_alert},
        {"availability", finite_or_null(m.integrity.availability)}}},
      {"recovery", recovery_json(m.recovery)},
      {"map_observations",
       {{"pose", observations_json(m.pose_observations)}, {"intensity", observations_json(m.intensity_observations)}}},
      {"mount_yaw", m.mount_yaw ? json{{"drawn_deg", m.mount_yaw->drawn_deg},
                                       {"learnt_deg", m.mount_yaw->learnt_deg},
                                       {"sigma_deg", m.mount_yaw->sigma_deg},
                                       {"error_deg", m.mount_yaw->error_deg},
                                       {"tolerance_deg", m.mount_yaw->tolerance_deg},
                                       {"settled_s", optional_or_null(m.mount_yaw->settled_s)}}
                                : json(nullptr)},
      {"thresholds",
       {{"against", m.thresholds.against_reference ? "reference" : "truth"},
        {"lateral_rmse_m", optional_or_null(m.thresholds.lateral_rmse_m)},
        {"longitudinal_rmse_m", optional_or_null(m.thresholds.longitudinal_rmse_m)},
        {"heading_rmse_deg", optional_or_null(m.thresholds.heading_rmse_deg)},
        {"max_position_error_m", optional_or_null(m.thresholds.max_position_error_m)},
        {"max_lane_offset_m", optional_or_null(m.thresholds.max_lane_offset_m)},
        {"settle_s", m.thresholds.settle_s},
        {"min_coverage", optional_or_null(m.thresholds.min_coverage)},
        {"max_misleading_fraction", optional_or_null(m.thresholds.max_misleading_fraction)},
        {"min_availability", optional_or_null(m.thresholds.min_availability)},
        {"alert_limit_lateral_m", m.thresholds.alert_limit_lateral_m},
        {"alert_limit_longitudinal_m", m.thresholds.alert_limit_longitudinal_m},
        {"min_mean_nees", optional_or_null(m.thresholds.min_mean_nees)},
        {"max_mean_nees", optional_or_null(m.thresholds.max_mean_nees)},
        {"recovery", m.thresholds.recovery ? json{{"position_m", m.thresholds.recovery->position_m},
                                                  {"within_s", m.thresholds.recovery->within_s},
                                                  {"lost_within_s", m.thresholds.recovery->lost_within_s}}
                                           : json(nullptr)}}},
      {"pass", m.pass},
      {"failures", m.failures},
  };
  return doc.dump(kJsonIndent) + "\n";
}

std::string curb_occlusion_text(const Metrics& m) {
  if (!std::isfinite(m.curb_hidden_fraction)) return "no curb sample in range in any scan (or not measured)";
  return "the traffic hid " + format("%.1f", 100 * m.curb_hidden_fraction) +
         "% of the curb samples in range (worst scan " + format("%.1f", 100 * m.curb_hidden_fraction_max) + "%)";
}

std::string consistency_text(const Metrics& m) {
  const Consistency& c = m.consistency;
  if (!std::isfinite(c.mean_nees_lateral) && !std::isfinite(c.mean_nees_longitudinal) &&
      !std::isfinite(c.mean_nees_heading))
    return "no covariance to check (no frame not lost with a positive variance)";
  return "mean NEES lateral " + cell(c.mean_nees_lateral, "%.2f") + ", longitudinal " +
         cell(c.mean_nees_longitudinal, "%.2f") + ", heading " + cell(c.mean_nees_heading, "%.2f") +
         " (1 when honest); beyond 3 sigma " + cell(100 * c.beyond_3_sigma_any, "%.2f%%") + " of " +
         std::to_string(c.frames) + " frames";
}

std::string integrity_text(const Metrics& m) {
  const Integrity& in = m.integrity;
  const std::string limits = "alert limits " + format("%.2f", m.thresholds.alert_limit_lateral_m) + " m lateral, " +
                             format("%.2f", m.thresholds.alert_limit_longitudinal_m) + " m longitudinal";
  if (in.frames_with_bounds == 0)
    return "no protection bounds given; available " + cell(100 * in.availability, "%.1f%%") + " (" + limits + ")";
  const std::string awaiting = in.frames_awaiting_alert == 0
                                   ? ""
                                   : " (and " + std::to_string(in.misleading_awaiting_alert) + " of " +
                                         std::to_string(in.frames_awaiting_alert) + " awaiting an alert given in time)";
  return "misleading " + std::to_string(in.misleading_frames) + " of " + std::to_string(in.frames_with_bounds) +
         " frames with bounds (" + cell(100 * in.misleading_fraction, "%.2f%%") + ")" + awaiting + ", available " +
         cell(100 * in.availability, "%.1f%%") + " (" + limits + ")";
}

std::string recovery_text(const EventRecovery& r) {
  return r.event.what + " at " + format("%.2f s", double(r.event.stamp_ns) / double(kNsPerS)) + ": converged after " +
         cell(r.converged_after_s, "%.2f s") + ", lost raised after " + cell(r.lost_raised_after_s, "%.2f s") +
         ", cleared after " + cell(r.lost_cleared_after_s, "%.2f s");
}

std::string reference_text(const Metrics& m) {
  if (!m.reference) return "none: scored against the truth only";
  const ReferenceAccuracy& r = *m.reference;
  return std::string(reference_kind_name(r.config.kind)) + " (" + format("%.3f m per axis, ", r.config.sigma_xy_m) +
         format("%.2f deg, ", r.config.heading_sigma_rad * kDegPerRad) +
         format("correlation %.0f s", r.config.correlation_s) + "): against it lateral RMSE " +
         cell(r.lateral_rmse_m, "%.3f m") + ", longitudinal RMSE " + cell(r.longitudinal_rmse_m, "%.3f m") +
         ", heading RMSE " + cell(r.heading_rmse_deg, "%.3f deg") + ", max position error " +
         cell(r.max_position_error_m, "%.3f m") + "; itself off the truth by " + cell(r.error_lateral_rms_m, "%.3f m") +
         " lateral, " + cell(r.error_longitudinal_rms_m, "%.3f m") + " longitudinal, " +
         cell(r.error_heading_rms_deg, "%.3f deg") + " heading (RMS)";
}

std::string reference_lines(const Metrics& m, const std::string& label) {
  if (!m.reference) return "";
  return "reference  " + (label.empty() ? "" : label + ": ") + reference_text(m) + "\n";
}

std::string latency_text(const Metrics& m) {
  return "localizer p50 " + cell(m.latency_p50_ms, "%.1f ms") + ", p99 " + cell(m.latency_p99_ms, "%.1f ms") +
         ", max " + cell(m.latency_max_ms, "%.1f ms") + "; the first scan, with the start-up, " +
         cell(m.latency_first_scan_ms, "%.1f ms");
}

std::string integrity_lines(const Metrics& m, const std::string& label) {
  const std::string who = label.empty() ? "" : label + ": ";
  std::string text = "nees       " + who + consistency_text(m) + "\nintegrity  " + who + integrity_text(m) + "\n";
  for (const EventRecovery& r : m.recovery) text += "recovery   " + who + recovery_text(r) + "\n";
  // The pose match is the curbs' (gicp: the point cloud's); intensity is APS's position.
  for (const auto& [name, o] :
       {std::pair{"pose match", &m.pose_observations}, std::pair{"intensity", &m.intensity_observations}}) {
    if (!*o) continue;
    const ObservationConsistency& c = **o;
    text +=
        std::string("observed   ") + who + name + ": mean NEES along " + cell(c.mean_nees(0), "%.2f") + " (" +
        std::to_string(c.counts(0)) + "), across " + cell(c.mean_nees(1), "%.2f") + " (" + std::to_string(c.counts(1)) +
        ")" +
        (c.counts(2) ? ", heading " + cell(c.mean_nees(2), "%.2f") + " (" + std::to_string(c.counts(2)) + ")" : "") +
        " of the observations the filter took, each against the truth\n";
  }
  if (const auto& y = m.mount_yaw) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "mount yaw  %slearnt %.3f deg, sigma %.3f, against the drawn %.3f deg: off by %.3f; ", who.c_str(),
                  y->learnt_deg, y->sigma_deg, y->drawn_deg, y->error_deg);
    text += line +
            (y->settled_s ? "within " + cell(y->tolerance_deg, "%.2f deg") + " from " + cell(*y->settled_s, "%.1f s")
                          : "not within " + cell(y->tolerance_deg, "%.2f deg") + " at the end") +
            "\n";
  }
  return text;
}

void write_metrics_json(const std::string& path, const Metrics& metrics) {
  write_text_file(path, metrics_json(metrics));
}

void write_errors_csv(const std::string& path, const ScoredRun& run, const std::vector<EstimateRecord>& estimates) {
  std::string text =
      "t_s,lateral_m,longitudinal_m,heading_deg,position_m,est_x_m,est_y_m,est_yaw_rad,truth_x_m,truth_y_m,"
      "truth_yaw_rad,status,latency_ms,sigma_x_m,sigma_y_m,sigma_yaw_deg,sigma_lateral_m,sigma_longitudinal_m,"
      "nees_lateral,nees_longitudinal,nees_heading,protection_lateral_m,protection_longitudinal_m,lost,misleading,"
      "awaiting_alert\n";
  for (size_t i = 0; i < run.errors.size(); ++i) {
    const FrameError& e = run.errors[i];
    const EstimateRecord& est = estimates.at(run.estimate_index.at(i));
    // A slightly negative variance from round-off is zero spread, not a NaN.
    auto sigma = [&](int k) { return std::sqrt(std::max(0.0, est.covariance(k, k))); };
    text += tum_seconds(e.stamp_ns) + ',' + number(e.lateral_m) + ',' + number(e.longitudinal_m) + ',' +
            number(e.heading_rad * kDegPerRad) + ',' + number(e.position_m) + ',' + number(e.estimate.x) + ',' +
            number(e.estimate.y) + ',' + number(e.estimate.yaw) + ',' + number(e.truth.x) + ',' + number(e.truth.y) +
            ',' + number(e.truth.yaw) + ',' + csv_field(est.status) + ',' + number(est.latency_ms) + ',' +
            number(sigma(0)) + ',' + number(sigma(1)) + ',' + number(sigma(2) * kDegPerRad) + ',' +
            number(e.sigma_lateral_m) + ',' + number(e.sigma_longitudinal_m) + ',' +
            number(nees(e.lateral_m, e.sigma_lateral_m)) + ',' +
            number(nees(e.longitudinal_m, e.sigma_longitudinal_m)) + ',' +
            number(nees(e.heading_rad, e.sigma_heading_rad)) + ',' + number(e.protection_lateral_m) + ',' +
            number(e.protection_longitudinal_m) + ',' + (e.lost ? '1' : '0') + ',' + (misleading(e) ? '1' : '0') + ',' +
            (e.awaiting_alert ? '1' : '0') + '\n';
  }
  write_text_file(path, text);
}

std::string tum_line(int64_t stamp_ns, const Pose2d& pose) {
  return tum_line(TumPose{stamp_ns, {pose.x, pose.y, 0}, ros2::yaw_quaternion(pose.yaw)});
}

void write_tum(const std::string& path, const std::vector<TruthPose>& poses) {
  std::string text = kTumHeader;
  for (const auto& p : poses) text += tum_line(p.stamp_ns, p.pose) + '\n';
  write_text_file(path, text);
}

void write_tum(const std::string& path, const std::vector<EstimateRecord>& estimates) {
  std::string text = kTumHeader;
  for (const auto& e : estimates) text += tum_line(e.stamp_ns, e.pose) + '\n';
  write_text_file(path, text);
}

std::string junit_xml(const std::vector<Metrics>& runs) {
  std::vector<std::string> scenarios;
  for (const auto& m : runs)
    if (std::find(scenarios.begin(), scenarios.end(), m.scenario) == scenarios.end()) scenarios.push_back(m.scenario);
  size_t total_failures = 0;
  for (const auto& m : runs) total_failures += m.pass ? 0 : 1;

  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites name=\"lidarloop\" tests=\"" + std::to_string(runs.size()) + "\" failures=\"" +
         std::to_string(total_failures) + "\">\n";
  for (const auto& scenario : scenarios) {
    size_t tests = 0, failures = 0;
    for (const auto& m : runs)
      if (m.scenario == scenario) tests++, failures += m.pass ? 0 : 1;
    xml += "  <testsuite name=\"" + xml_escaped(scenario) + "\" tests=\"" + std::to_string(tests) + "\" failures=\"" +
           std::to_string(failures) + "\" errors=\"0\">\n";
    for (const auto& m : runs) {
      if (m.scenario != scenario) continue;
      xml += "    <testcase name=\"" + xml_escaped(m.method) + "\" classname=\"lidarloop." + xml_escaped(scenario) +
             "\">\n";
      if (!m.pass)
        xml += "      <failure message=\"" + xml_escaped(joined(m.failures, "; ")) + "\" type=\"thresholds\">" +
               xml_escaped(joined(m.failures, "\n")) + "</failure>\n";
      xml += "      <system-out>" + xml_escaped(summary(m)) + "</system-out>\n";
      xml += "    </testcase>\n";
    }
    xml += "  </testsuite>\n";
  }
  return xml + "</testsuites>\n";
}

void write_junit(const std::string& path, const std::vector<Metrics>& runs) { write_text_file(path, junit_xml(runs)); }

std::string comparison_markdown(const std::vector<Metrics>& runs) {
  bool several_scenarios = false;
  for (const auto& m : runs) several_scenarios |= m.scenario != runs.front().scenario;
  const std::string first = several_scenarios ? "| scenario " : "";
  std::string md =
      first +
      "| method | lateral RMSE m | longitudinal RMSE m | heading RMSE deg | max error m | latency p50 ms | "
      "coverage | pass |\n" +
      (several_scenarios ? "|---" : "") + "|---|---:|---:|---:|---:|---:|---:|:---:|\n";
  for (const auto& m : runs) {
    if (several_scenarios) md += "| " + markdown_cell(m.scenario) + ' ';
    md += "| " + markdown_cell(m.method) + " | " + cell(m.lateral_rmse_m, "%.3f") + " | " +
          cell(m.longitudinal_rmse_m, "%.3f") + " | " + cell(m.heading_rmse_deg, "%.3f") + " | " +
          cell(m.max_position_error_m, "%.3f") + " | " + cell(m.latency_p50_ms, "%.2f") + " | " +
          cell(100 * m.coverage, "%.1f%%") + " | " + (m.pass ? "pass" : "FAIL") + " |\n";
  }
  return md;
}

std::string reference_markdown(const std::vector<Metrics>& runs) {
  bool any = false, several_scenarios = false;
  for (const auto& m : runs) {
    any |= m.reference.has_value();
    several_scenarios |= m.scenario != runs.front().scenario;
  }
  if (!any) return "";
  std::string md = std::string(several_scenarios ? "| scenario " : "") +
                   "| method | lateral RMSE m: truth | reference | longitudinal RMSE m: truth | reference | "
                   "heading RMSE deg: truth | reference | max error m: truth | reference |\n" +
                   (several_scenarios ? "|---" : "") + "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& m : runs) {
    if (!m.reference) continue;
    const ReferenceAccuracy& r = *m.reference;
    if (several_scenarios) md += "| " + markdown_cell(m.scenario) + ' ';
    md += "| " + markdown_cell(m.method) + " | " + cell(m.lateral_rmse_m, "%.3f") + " | " +
          cell(r.lateral_rmse_m, "%.3f") + " | " + cell(m.longitudinal_rmse_m, "%.3f") + " | " +
          cell(r.longitudinal_rmse_m, "%.3f") + " | " + cell(m.heading_rmse_deg, "%.3f") + " | " +
          cell(r.heading_rmse_deg, "%.3f") + " | " + cell(m.max_position_error_m, "%.3f") + " | " +
          cell(r.max_position_error_m, "%.3f") + " |\n";
  }
  return md;
}

void write_comparison_csv(const std::string& path, const std::vector<Metrics>& runs) {
  std::string text =
      "scenario,method,frames,lateral_rmse_m,longitudinal_rmse_m,heading_rmse_deg,max_position_error_m,"
      "latency_p50_ms,latency_p99_ms,pass\n";
  for (const auto& m : runs)
    text += csv_field(m.scenario) + ',' + csv_field(m.method) + ',' + std::to_string(m.frames) + ',' +
            number(m.lateral_rmse_m) + ',' + number(m.longitudinal_rmse_m) + ',' + number(m.heading_rmse_deg) + ',' +
            number(m.max_position_error_m) + ',' + number(m.latency_p50_ms) + ',' + number(m.latency_p99_ms) + ',' +
            (m.pass ? "true" : "false") + '\n';
  write_text_file(path, text);
}

}  // namespace lidarloop
