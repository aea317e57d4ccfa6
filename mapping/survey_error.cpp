#include "mapping/survey_error.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace lidarloop {

std::string exact_number(double v) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  return std::string(buffer, end);
}

namespace {

// One exact-discretisation step of a first-order Gauss-Markov process (see the header).
double gauss_markov_step(double e, double ds, double sigma, double length, double n) {
  const double phi = std::exp(-ds / length);
  return phi * e + sigma * std::sqrt(1.0 - phi * phi) * n;
}

}  // namespace

const char* map_provenance_name(MapProvenance provenance) {
  switch (provenance) {
    case MapProvenance::rtk_ins:
      return "rtk_ins";
    case MapProvenance::slam:
      return "slam";
  }
  return "?";
}

std::string SurveyErrorConfig::describe() const {
  const std::string provenance_text =
      provenance == MapProvenance::rtk_ins
          ? ""
          : std::string(" provenance=") + map_provenance_name(provenance) + " " + slam.describe();
  return "sigma_xy_m=" + exact_number(sigma_xy_m) + " correlation_length_m=" + exact_number(correlation_length_m) +
         " heading_sigma_deg=" + exact_number(heading_sigma_rad * kDegPerRad) +
         " heading_correlation_length_m=" + exact_number(heading_correlation_length_m) +
         " sample_spacing_m=" + exact_number(sample_spacing_m) + provenance_text;
}

SurveyErrorTrack simulate_survey_error(const SurveyErrorConfig& c, double length_m, std::mt19937_64& rng) {
  if (!(c.sigma_xy_m >= 0 && c.heading_sigma_rad >= 0 && c.correlation_length_m > 0 &&
        c.heading_correlation_length_m > 0 && c.sample_spacing_m > 0 && length_m >= 0))
    throw std::invalid_argument("survey error: sigmas must not be negative, lengths and spacing must be positive");
  SurveyErrorTrack track;
  track.spacing_m = c.sample_spacing_m;
  const size_t n = size_t(std::ceil(length_m / c.sample_spacing_m)) + 1;
  track.samples.reserve(n);
  std::normal_distribution<double> normal(0.0, 1.0);
  Pose2d e;
  for (size_t k = 0; k < n; ++k) {
    const double n_east = normal(rng), n_north = normal(rng), n_heading = normal(rng);
    if (k == 0) {
      e = {c.sigma_xy_m * n_east, c.sigma_xy_m * n_north, c.heading_sigma_rad * n_heading};
    } else {
      const double ds = c.sample_spacing_m;
      e.x = gauss_markov_step(e.x, ds, c.sigma_xy_m, c.correlation_length_m, n_east);
      e.y = gauss_markov_step(e.y, ds, c.sigma_xy_m, c.correlation_length_m, n_north);
      e.yaw = gauss_markov_step(e.yaw, ds, c.heading_sigma_rad, c.heading_correlation_length_m, n_heading);
    }
    track.samples.push_back(e);
  }
  return track;
}

Pose2d SurveyErrorTrack::at(double s) const {
  if (samples.empty()) return {};
  const double u = std::clamp(s / spacing_m, 0.0, double(samples.size() - 1));
  const size_t i = std::min(size_t(u), samples.size() - 1);
  if (i + 1 == samples.size()) return samples.back();
  const double f = u - double(i);
  const Pose2d& a = samples[i];
  const Pose2d& b = samples[i + 1];
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), a.yaw + f * (b.yaw - a.yaw)};
}

Pose2d surveyed_pose(const Pose2d& truth, const Pose2d& error) {
  return {truth.x + error.x, truth.y + error.y, wrap_angle(truth.yaw + error.yaw)};
}

Eigen::Vector2d surveyed_point(const Eigen::Vector2d& p, const Eigen::Vector2d& truth_xy, const Pose2d& error) {
  const double c = std::cos(error.yaw), s = std::sin(error.yaw);
  const Eigen::Vector2d r = p - truth_xy;
  const Eigen::Vector2d turned((c - 1.0) * r.x() - s * r.y(), s * r.x() + (c - 1.0) * r.y());
  return p + (Eigen::Vector2d(error.x, error.y) + turned);
}

}  // namespace lidarloop
