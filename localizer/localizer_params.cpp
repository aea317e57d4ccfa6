#include "localizer/localizer_params.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <stdexcept>

namespace lidarloop {
namespace {

void read_icp(const YamlReader& y, const YAML::Node& n, const char* name, IcpParams& p) {
  YamlMap(y, n, name)
      .integer("max_iterations", p.max_iterations, 1, 1000)
      .number("convergence", p.convergence, 1e-9, 1.0)
      .number("max_correspondence", p.max_correspondence, 0.01, 100.0)
      .done();
}

}  // namespace

bool uses_curbs(LocalizerMethod m) {
  return m == LocalizerMethod::icp || m == LocalizerMethod::icp_obs || m == LocalizerMethod::m_icp ||
         m == LocalizerMethod::fmt || m == LocalizerMethod::proposed;
}
bool uses_intensity(LocalizerMethod m) { return m == LocalizerMethod::intensity || m == LocalizerMethod::proposed; }
// gicp registers the whole scan: what moves finds no partner in the map and drops out of its fitness.
bool removes_obstacles(LocalizerMethod m) {
  return m != LocalizerMethod::icp && m != LocalizerMethod::gps && m != LocalizerMethod::gicp;
}

std::vector<std::string> split_command_line(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote)
        quote = 0;
      else if (c == '\\' && quote == '"' && i + 1 < text.size() && (text[i + 1] == '"' || text[i + 1] == '\\'))
        word += text[++i];
      else
        word += c;
    } else if (c == '\'' || c == '"') {
      quote = c;
      in_word = true;
    } else if (c == '\\') {
      if (i + 1 == text.size()) throw std::invalid_argument("command line ends with a backslash: " + text);
      word += text[++i];
      in_word = true;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      if (in_word) words.push_back(std::move(word));
      word.clear();
      in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (quote) throw std::invalid_argument(std::string("unterminated ") + quote + " in command line: " + text);
  if (in_word) words.push_back(std::move(word));
  return words;
}

void set_method(LocalizerParams& params, const std::string& text) {
  static const std::string exec = "exec:";
  if (text.rfind(exec, 0) == 0) {
    std::vector<std::string> command = split_command_line(text.substr(exec.size()));
    if (command.empty()) throw std::invalid_argument("method '" + text + "': no program after exec:");
    params.external.command = std::move(command);
    return;
  }
  params.method = parse_localizer_method(text);
  params.external.command.clear();
}

LatencyParams parse_latency(const std::string& text) {
  if (text == "one_scan") return {LatencyModel::one_scan, 0};
  if (text == "measured") return {LatencyModel::measured, 0};
  constexpr double kMaxLatencyMs = 60000;  // a minute per scan: beyond it, a typo
  double ms = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), ms);
  if (ec != std::errc() || end != text.data() + text.size() || !(ms >= 0 && ms <= kMaxLatencyMs))
    throw std::invalid_argument("latency '" + text +
                                "': expected one_scan, measured, or milliseconds per scan from 0 to 60000");
  return {LatencyModel::fixed, ms};
}

std::string latency_text(const LatencyParams& latency) {
  switch (latency.model) {
    case LatencyModel::automatic:
      return "automatic";
    case LatencyModel::one_scan:
      return "one_scan";
    case LatencyModel::measured:
      return "measured";
    case LatencyModel::fixed:
      break;
  }
  char text[32];
  std::snprintf(text, sizeof text, "%g ms", latency.fixed_ms);
  return text;
}

std::string method_label(const LocalizerParams& params) {
  const auto& command = params.external.command;
  if (command.empty()) return method_name(params.method);
  const auto file_name = [](const std::string& path) { return path.substr(path.find_last_of('/') + 1); };
  std::string label = "exec-" + file_name(command[0]);
  if (command.size() > 1 && command[1].rfind('-', 0) != 0) label.append(1, '-').append(file_name(command[1]));
  for (char& c : label)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  return label;
}

std::string method_label(const std::string& method_text) {
  LocalizerParams params;
  set_method(params, method_text);
  return method_label(params);
}

std::string method_text(const LocalizerParams& params) {
  if (params.external.command.empty()) return method_name(params.method);
  std::string text = "exec:";
  for (size_t i = 0; i < params.external.command.size(); ++i) {
    const std::string& word = params.external.command[i];
    const bool plain = !word.empty() && word.find_first_of(" \t\n'\"\\") == std::string::npos;
    std::string quoted = "'";
    for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    text += (i ? " " : "") + (plain ? word : quoted + "'");
  }
  return text;
}

void read_localizer_params(const YamlReader& y, const YAML::Node& node, LocalizerParams& p) {
  if (!node) return;
  YamlMap top(y, node, "localizer");
  top.boolean("deskew", p.deskew).number("map_window_m", p.map_window_m, 5.0, 200.0);
  top.number("max_prediction_step_s", p.max_prediction_step_s, 1e-4, 0.1);
  top.number("process_position_without_can_per_s", p.process_position_without_can_per_s, 0.0, 100.0);
  top.number("aps_window_sigmas", p.aps_window_sigmas, 0.0, 100.0);
  top.number("icp_window_sigmas", p.icp_window_sigmas, 0.0, 100.0);
  top.number("aps_covariance_scale", p.aps_covariance_scale, 1e-3, 1e3);
  top.boolean("aps_longitudinal_only_with_curbs", p.aps_longitudinal_only_with_curbs);
  top.number("aps_max_spread_ratio", p.aps_max_spread_ratio, 0.0, 10.0);
  top.number("aps_min_along_margin", p.aps_min_along_margin, 0.0, 1e9);
  top.number("aps_grown_within_sigmas", p.aps_grown_within_sigmas, 0.0, 100.0);
  top.number("icp_max_correspondence_m", p.icp_max_correspondence_m, 0.1, 100.0);
  top.number("aps_max_lateral_range_m", p.aps_max_lateral_range_m, 0.0, 50.0);
  top.number("aps_max_longitudinal_range_m", p.aps_max_longitudinal_range_m, 0.0, 50.0);
  if (const YAML::Node m = top["method"]) {
    try {
      set_method(p, y.string(m, "method"));
    } catch (const std::invalid_argument& e) {
      y.fail(m, e.what());
    }
  }
  top.integer("seed", p.seed, 0, uint64_t(1) << 62);
  if (const YAML::Node l = top["latency"]) {
    try {
      p.latency = parse_latency(y.string(l, "latency"));
    } catch (const std::invalid_argument& e) {
      y.fail(l, e.what());
    }
  }

  YamlMap(y, top["external"], "external")
      .number("deadline_ms", p.external.deadline_ms, 1.0, 60000.0)
      .number("startup_timeout_s", p.external.startup_timeout_s, 0.1, 600.0)
      .number("exit_timeout_s", p.external.exit_timeout_s, 0.1, 600.0)
      .done();
  YamlMap(y, top["corridor"], "corridor")
      .integer("width_cells", p.corridor.width_cells, 10, 4000)
      .integer("height_cells", p.corridor.height_cells, 10, 4000)
      .number("cell_m", p.corridor.cell_m, 0.01, 2.0)
      .integer("dilation_cells", p.corridor.dilation_cells, 0, 50)
      .done();
  YamlMap(y, top["obstacles"], "obstacles")
      .number("ground_fraction", p.obstacles.ground_fraction, 0.01, 1.0)
      .number("obstacle_distance", p.obstacles.obstacle_distance, 0.01, 10.0)
      .number("ground_cell_m", p.obstacles.ground_cell_m, 0.05, 20.0)
      .number("ground_refit_distance", p.obstacles.ground_refit_distance, 0.01, 10.0)
      .done();
  YamlMap(y, top["curb_detector"], "curb_detector")
      .number("min_height", p.curb_detector.min_height, 0.0, 1.0)
      .number("max_height", p.curb_detector.max_height, 0.01, 2.0)
      .number("step_length", p.curb_detector.step_length, 0.01, 5.0)
      .number("flat_length", p.curb_detector.flat_length, 0.01, 5.0)
      .number("max_flat_roughness", p.curb_detector.max_flat_roughness, 0.0, 1.0)
      .number("max_range", p.curb_detector.max_range, 1.0, 100.0)
      .number("max_ground_height", p.curb_detector.max_ground_height, 0.0, 5.0)
      .done();
  YamlMap(y, top["curb_features"], "curb_features")
      .integer("frames", p.curb_features.frames, 1, 100)
      .number("obstacle_distance", p.curb_features.obstacle_distance, 0.0, 10.0)
      .integer("beams", p.curb_features.beams, 1, 3600)
      .number("beam_half_extent", p.curb_features.beam_half_extent, 1.0, 100.0)
      .done();
  {
    YamlMap picp(y, top["probabilistic_icp"], "probabilistic_icp");
    picp.integer("n_p", p.probabilistic_icp.n_p, 1, 10000)
        .integer("n_t", p.probabilistic_icp.n_t, 1, 10000)
        .number("d_g", p.probabilistic_icp.d_g, 0.01, 100.0)
        .number("outlier_softness_curbs", p.probabilistic_icp.outlier_softness_curbs, 0.0, 1000.0);
    read_icp(y, picp["local"], "local", p.probabilistic_icp.local);
    read_icp(y, picp["global"], "global", p.probabilistic_icp.global);
    picp.done();
  }
  read_icp(y, top["icp"], "icp", p.icp);
  {
    YamlMap m_icp(y, top["m_icp"], "m_icp");
    m_icp.number("biweight_b", p.m_icp.biweight_b, 0.1, 100.0).number("scale_m", p.m_icp.scale_m, 0.001, 100.0);
    read_icp(y, m_icp["icp"], "icp", p.m_icp.icp);
    m_icp.done();
  }
  YamlMap(y, top["fmt"], "fmt")
      .integer("size_cells", p.fmt.size_cells, 16, 4096)
      .number("cell_m", p.fmt.cell_m, 0.01, 2.0)
      .number("blur_sigma_cells", p.fmt.blur_sigma_cells, 0.0, 20.0)
      .integer("angle_bins", p.fmt.angle_bins, 8, 7200)
      .number("min_radius_fraction", p.fmt.min_radius_fraction, 0.0, 1.0)
      .number("max_radius_fraction", p.fmt.max_radius_fraction, 0.0, 1.0)
      .integer("min_points", p.fmt.min_points, 1, 100000)
      .number("min_response", p.fmt.min_response, 0.0, 1.0)
      .done();
  YamlMap(y, top["gicp"], "gicp")
      .number("scan_voxel_m", p.gicp.scan_voxel_m, 0.05, 10.0)
      .number("max_range_m", p.gicp.max_range_m, 1.0, 200.0)
      .number("min_height_m", p.gicp.min_height_m, -100.0, 0.0)
      .integer("covariance_neighbours", p.gicp.covariance_neighbours, 3, 1000)
      .number("epsilon", p.gicp.epsilon, 1e-9, 1.0)
      .number("max_correspondence_m", p.gicp.max_correspondence_m, 0.01, 100.0)
      .number("window_sigmas", p.gicp.window_sigmas, 0.0, 100.0)
      .number("max_correspondence_widened_m", p.gicp.max_correspondence_widened_m, 0.01, 100.0)
      .number("relative_fitness", p.gicp.relative_fitness, 0.0, 1.0)
      .number("relative_rmse", p.gicp.relative_rmse, 0.0, 1.0)
      .integer("max_iterations", p.gicp.max_iterations, 1, 1000)
      .number("converged_translation_m", p.gicp.converged_translation_m, 0.0, 100.0)
      .number("converged_rotation_rad", p.gicp.converged_rotation_rad, 0.0, 3.2)
      .number("target_reuse_m", p.gicp.target_reuse_m, 0.0, 1000.0)
      .number("covariance_reuse_margin_m", p.gicp.covariance_reuse_margin_m, 0.0, 1000.0)
      .integer("min_scan_points", p.gicp.min_scan_points, 0, 10000000)
      .integer("min_map_points", p.gicp.min_map_points, 0, 100000000)
      .number("min_fitness", p.gicp.min_fitness, 0.0, 1.0)
      .number("map_sigma_m", p.gicp.map_sigma_m, 0.0, 100.0)
      .number("map_sigma_yaw_rad", p.gicp.map_sigma_yaw_rad, 0.0, 3.2)
      .done();
  YamlMap(y, top["intensity_grid"], "intensity_grid")
      .integer("width_cells", p.intensity_grid.width_cells, 10, 4000)
      .integer("height_cells", p.intensity_grid.height_cells, 10, 4000)
      .number("cell_m", p.intensity_grid.cell_m, 0.01, 2.0)
      .number("max_height", p.intensity_grid.max_height, 0.01, 10.0)
      .integer("frames", p.intensity_grid.frames, 1, 100)
      .number("obstacle_distance", p.intensity_grid.obstacle_distance, 0.0, 10.0)
      .number("max_turn_deg", p.intensity_grid.max_turn_deg, 0.0, 180.0)
      .done();
  YamlMap(y, top["intensity_calibration"], "intensity_calibration")
      .boolean("enabled", p.intensity_calibration.enabled)
      .number("forgetting", p.intensity_calibration.forgetting, 0.0, 1.0)
      .number("prior_points", p.intensity_calibration.prior_points, 1.0, 1e9)
      .number("prior_dark", p.intensity_calibration.prior_dark, 0.0, 255.0)
      .number("prior_bright", p.intensity_calibration.prior_bright, 0.0, 255.0)
      .integer("min_map_count", p.intensity_calibration.min_map_count, 1, 1000000)
      .number("max_position_sigma_m", p.intensity_calibration.max_position_sigma_m, 0.0, 100.0)
      .integer("point_stride", p.intensity_calibration.point_stride, 1, 1000)
      .number("min_gain", p.intensity_calibration.min_gain, 0.01, 1.0)
      .number("max_gain", p.intensity_calibration.max_gain, 1.0, 100.0)
      .done();
  if (!(p.intensity_calibration.prior_bright > p.intensity_calibration.prior_dark))
    y.fail(top["intensity_calibration"], "intensity_calibration: prior_bright must exceed prior_dark");
  YamlMap(y, top["aps"], "aps")
      .number("lateral_range_m", p.aps.lateral_range_m, 0.0, 20.0)
      .number("longitudinal_range_m", p.aps.longitudinal_range_m, 0.0, 20.0)
      .number("step_m", p.aps.step_m, 0.01, 5.0)
      .number("alpha", p.aps.alpha, 1e-6, 100.0)
      .integer("min_count", p.aps.min_count, 0, 100000)
      .number("min_sigma", p.aps.min_sigma, 1e-6, 255.0)
      .integer("min_cells", p.aps.min_cells, 0, 1000000)
      .number("distinct_separation_m", p.aps.distinct_separation_m, 0.0, 20.0)
      .done();
  YamlMap(y, top["vehicle"], "vehicle")
      .number("cornering_stiffness_front", p.vehicle.cornering_stiffness_front, 1e3, 1e6)
      .number("cornering_stiffness_rear", p.vehicle.cornering_stiffness_rear, 1e3, 1e6)
      .number("lf", p.vehicle.lf, 0.1, 10.0)
      .number("lr", p.vehicle.lr, 0.1, 10.0)
      .number("yaw_inertia", p.vehicle.yaw_inertia, 10.0, 1e6)
      .number("mass", p.vehicle.mass, 10.0, 1e5)
      .number("steering_ratio", p.vehicle.steering_ratio, 1.0, 50.0)
      .number("kinematic_below", p.vehicle.kinematic_below, 0.0, 10.0)
      .done();
  YamlMap(y, top["body_roll"], "body_roll")
      .boolean("enabled", p.body_roll.enabled)
      .number("gradient_deg_per_g", p.body_roll.gradient_deg_per_g, 0.0, 90.0)
      .number("frequency_hz", p.body_roll.frequency_hz, 0.1, 10.0)
      .number("damping_ratio", p.body_roll.damping_ratio, 0.01, 2.0)
      .number("pivot_height_m", p.body_roll.pivot_height_m, 0.0, 10.0)
      .done();
  YamlMap(y, top["filter"], "filter")
      .number("position_per_sqrt_m", p.filter.position_per_sqrt_m, 0.0, 10.0)
      .number("yaw_per_sqrt_m", p.filter.yaw_per_sqrt_m, 0.0, 1.0)
      .number("yaw_per_sqrt_rad", p.filter.yaw_per_sqrt_rad, 0.0, 1.0)
      .number("position_per_sqrt_s", p.filter.position_per_sqrt_s, 0.0, 10.0)
      .done();
  YamlMap(y, top["curb_noise"], "curb_noise")
      .number("min_point_sigma_m", p.curb_noise.min_point_sigma_m, 1e-4, 10.0)
      .number("correlation_length_m", p.curb_noise.correlation_length_m, 0.01, 100.0)
      .number("inlier_distance_m", p.curb_noise.inlier_distance_m, 0.01, 100.0)
      .number("min_sigma_m", p.curb_noise.min_sigma_m, 0.0, 10.0)
      .number("min_sigma_yaw_rad", p.curb_noise.min_sigma_yaw_rad, 0.0, 1.0)
      .number("unconstrained_sigma_m", p.curb_noise.unconstrained_sigma_m, 1.0, 1e6)
      .integer("refine_iterations", p.curb_noise.refine_iterations, 0, 100)
      .done();
  YamlMap gps_noise(y, top["gps_noise"], "gps_noise");
  gps_noise.number("min_sigma_m", p.gps_noise.min_sigma_m, 0.0, 100.0)
      .number("min_heading_sigma_rad", p.gps_noise.min_heading_sigma_rad, 0.0, 3.2)
      .number("variance_scale", p.gps_noise.variance_scale, 1e-3, 1e6)
      .boolean("bias_state", p.gps_noise.bias_state)
      .number("bias_tau_s", p.gps_noise.bias_tau_s, 0.1, 1e5)
      .number("heading_bias_tau_s", p.gps_noise.heading_bias_tau_s, 0.1, 1e5);
  YamlMap(y, gps_noise["jitter"], "gps_noise.jitter")
      .integer("window", p.gps_noise.jitter.window, 1, 1000000)
      .integer("min_samples", p.gps_noise.jitter.min_samples, 1, 1000000)
      .number("gate_xy", p.gps_noise.jitter.gate_xy, 1.0, 1e6)
      .number("gate_yaw", p.gps_noise.jitter.gate_yaw, 1.0, 1e6)
      .done();
  gps_noise.done();
  YamlMap(y, top["health"], "health")
      .number("gps_timeout_s", p.health.gps_timeout_s, 0.01, 1e4)
      .number("can_timeout_s", p.health.can_timeout_s, 0.001, 1e4)
      .integer("min_scan_points", p.health.min_scan_points, 0, 10000000)
      .integer("min_curbs", p.health.min_curbs, 1, 100000)
      .number("min_inlier_ratio", p.health.min_inlier_ratio, 0.0, 1.0)
      .number("gate_curb", p.health.gate_curb, 0.0, 1e9)
      .number("gate_intensity", p.health.gate_intensity, 0.0, 1e9)
      .number("gate_gps", p.health.gate_gps, 0.0, 1e9)
      .integer("max_rejections", p.health.max_rejections, 0, 1000000)
      .number("max_inflated_sigma_m", p.health.max_inflated_sigma_m, 0.0, 1000.0)
      .done();
  YamlMap(y, top["gps_steps"], "gps_steps")
      .number("level_tau_s", p.gps_steps.level_tau_s, 0.01, 1e4)
      .number("min_noise_sigma_m", p.gps_steps.min_noise_sigma_m, 0.001, 100.0)
      .number("step_gate", p.gps_steps.step_gate, 0.1, 1e6)
      .done();
  YamlMap(y, top["mount_uncertainty"], "mount_uncertainty")
      .number("yaw_sigma_deg", p.mount_uncertainty.yaw_sigma_deg, 0.0, 90.0)
      .number("translation_sigma_m", p.mount_uncertainty.translation_sigma_m, 0.0, 10.0)
      .boolean("learn_yaw", p.mount_uncertainty.learn_yaw)
      .done();
  YamlMap(y, top["lost"], "lost")
      .number("window_s", p.lost.window_s, 0.01, 100.0)
      .integer("min_disagreements", p.lost.min_disagreements, 1, 1000)
      .integer("confirmations", p.lost.confirmations, 1, 1000)
      .number("converged_sigma_m", p.lost.converged_sigma_m, 0.001, 100.0)
      .done();
  YamlMap(y, top["relocalization"], "relocalization")
      .number("window_sigmas", p.relocalization.window_sigmas, 0.1, 100.0)
      .number("lost_offset_sigmas", p.relocalization.lost_offset_sigmas, 0.1, 100.0)
      .number("max_yaw_deg", p.relocalization.max_yaw_deg, 0.0, 90.0)
      .number("min_curb_score", p.relocalization.min_curb_score, 0.0, 1.0)
      .number("min_aps_margin", p.relocalization.min_aps_margin, 0.0, 1e9)
      .number("min_prior_gap", p.relocalization.min_prior_gap, 0.0, 1e9)
      .number("max_prior_term", p.relocalization.max_prior_term, 0.0, 1e9)
      .number("confirm_distance_m", p.relocalization.confirm_distance_m, 0.0, 100.0)
      .number("confirm_yaw_deg", p.relocalization.confirm_yaw_deg, 0.0, 90.0)
      .number("along_road_lateral_m", p.relocalization.along_road_lateral_m, 0.0, 100.0)
      .number("along_road_yaw_deg", p.relocalization.along_road_yaw_deg, 0.0, 90.0)
      .number("min_range_m", p.relocalization.min_range_m, 0.0, 100.0)
      .number("max_longitudinal_m", p.relocalization.max_longitudinal_m, 0.0, 100.0)
      .number("max_lateral_m", p.relocalization.max_lateral_m, 0.0, 100.0)
      .number("lost_yaw_sigma_deg", p.relocalization.lost_yaw_sigma_deg, 0.0, 90.0)
      .done();
  YamlMap(y, top["integrity"], "integrity").number("probability", p.integrity.probability, 0.5, 1.0 - 1e-12).done();
  top.done();
}

}  // namespace lidarloop
