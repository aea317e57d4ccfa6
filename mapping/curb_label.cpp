#include "mapping/curb_label.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

#include "common/points_kd_tree.hpp"
#include "mapping/survey_error.hpp"

namespace lidarloop {

namespace {

// m: a curb point farther than this from every cross-section of the band has none of its own (the
// band's cross-sections are 0.5 m apart along the very lines the map's curbs are drawn from).
constexpr double kMaxStationDistance = 1.0;

// The unit normal of `line` at vertex i (the mean direction of its neighbouring segments turned left);
// a closed line (first point repeated last) wraps round. Zero where the line has no length there.
Eigen::Vector2d left_normal(const Polyline2d& line, size_t i) {
  const size_t n = line.size();
  const bool closed = n > 2 && line.front() == line.back();
  const size_t prev = i > 0 ? i - 1 : (closed ? n - 2 : 0);
  const size_t next = i + 1 < n ? i + 1 : (closed ? 1 : n - 1);
  const Eigen::Vector2d along = line[next] - line[prev];
  const double length = along.norm();
  if (!(length > 0)) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(-along.y(), along.x()) / length;
}

}  // namespace

const char* curb_label_name(CurbLabel label) {
  switch (label) {
    case CurbLabel::face_foot:
      return "face_foot";
    case CurbLabel::face_top:
      return "face_top";
    case CurbLabel::gutter_line:
      return "gutter_line";
  }
  return "?";
}

bool CurbLabelConfig::is_default() const { return convention == CurbLabel::face_foot && noise_m == 0; }

std::string CurbLabelConfig::describe() const {
  if (is_default()) return "";
  return std::string("curb_label=") + curb_label_name(convention) + " label_noise_m=" + exact_number(noise_m) +
         " label_noise_correlation_m=" + exact_number(noise_correlation_m);
}

double curb_label_offset(CurbLabel label, CurbProfile profile, double height, double gutter_width) {
  switch (label) {
    case CurbLabel::face_foot:
      return 0;
    case CurbLabel::face_top:
      return face_run(profile, height);
    case CurbLabel::gutter_line:
      return -gutter_width;
  }
  return 0;
}

CurbMap label_curb_map(const CurbMap& map, const std::vector<std::vector<CurbStation>>& rings, const CurbLabelConfig& c,
                       std::mt19937_64& rng) {
  if (!(c.noise_m >= 0 && c.noise_correlation_m > 0))
    throw std::invalid_argument("curb label: the noise must not be negative, its correlation length must be positive");
  if (c.is_default()) return map;
  std::vector<const CurbStation*> stations;
  std::vector<Eigen::Vector2d> points;
  for (const auto& ring : rings)
    for (const CurbStation& s : ring) stations.push_back(&s), points.push_back(s.point);
  std::optional<PointsKdTree> index;  // none without cross-sections
  if (!points.empty()) index.emplace(&points);
  std::normal_distribution<double> normal(0.0, 1.0);
  CurbMap out = map;
  for (size_t k = 0; k < map.curbs.size(); ++k) {
    const Polyline2d& line = map.curbs[k];
    Polyline2d& moved = out.curbs[k];
    const bool closed = line.size() > 2 && line.front() == line.back();
    double noise = 0;
    for (size_t i = 0; i < line.size(); ++i) {
      // The labelling noise: Gauss-Markov over the arc length (mapping/survey_error.hpp's process).
      const double n = normal(rng);
      if (i == 0) {
        noise = c.noise_m * n;
      } else {
        const double phi = std::exp(-(line[i] - line[i - 1]).norm() / c.noise_correlation_m);
        noise = phi * noise + c.noise_m * std::sqrt(1 - phi * phi) * n;
      }
      Eigen::Vector2d normal_out = left_normal(line, i);
      double offset = 0;
      uint32_t nearest = 0;
      double d2 = 0;
      if (index && index->tree.knnSearch(line[i].data(), 1, &nearest, &d2) == 1 &&
          d2 <= kMaxStationDistance * kMaxStationDistance) {
        const CurbStation& s = *stations[nearest];
        if (normal_out.dot(s.normal) < 0) normal_out = -normal_out;  // away from the carriageway
        offset = curb_label_offset(c.convention, s.profile, s.height, s.gutter_width);
      }
      // Without a cross-section the side is unknown: the noise alone, to the line's left.
      moved[i] = line[i] + normal_out * (offset + noise);
    }
    if (closed) moved.back() = moved.front();  // a ring stays closed
  }
  return out;
}

}  // namespace lidarloop
