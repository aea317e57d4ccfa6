#include "sim/road_surface.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "common/points_kd_tree.hpp"
#include "sim/polyline.hpp"
#include "sim/superelevation.hpp"

namespace lidarloop {
namespace {

constexpr double kSampleStep = 0.5;             // m between centreline samples
constexpr size_t kNearestSamples = 4;           // enough to see two roads at once where they meet
constexpr size_t kNearestCandidates = 16;       // samples weighed when attributing a point to a road
constexpr double kBeyondEndPenalty = 1.0;       // m added to the distance past an open road's end
constexpr int kRoughnessWaves = 32;             // plane waves summed for the roughness field
constexpr double kIsoReferenceFrequency = 0.1;  // cycles/m, n0 of ISO 8608
constexpr double kIsoWaviness = 2.0;            // w of ISO 8608: G(n) = G(n0) (n / n0)^-w

// Distance from p to the centreline near sample c (beside it: the perpendicular offset).
double lateral_offset(const Eigen::Vector2d& p, const Eigen::Vector2d& c, const Eigen::Vector2d& t) {
  const Eigen::Vector2d d = p - c;
  return t.x() * d.y() - t.y() * d.x();
}

}  // namespace

// ISO 8608:2016 Table 1, geometric mean of each class: 16, 64, 256, 1024, 4096 x 1e-6 m^3.
double iso8608_psd(char road_class) {
  if (road_class < 'A' || road_class > 'E') return 0;
  return 16e-6 * std::pow(4.0, road_class - 'A');
}

RoadSurface::RoadSurface(const WorldDescription& d) : hills_(d.hills) {
  for (size_t r = 0; r < d.roads.size(); ++r) {
    const RoadSpec& road = d.roads[r];
    cross_slope_.push_back(road.cross_slope);
    const double length = polyline_length(road.centreline);
    const int n = std::max(1, int(std::ceil(length / kSampleStep)));
    std::vector<double> arc;
    for (int i = 0; i <= n; ++i) arc.push_back(length * i / n);
    const std::vector<double> bank =
        superelevation_profile(road.centreline, road.closed, arc, road.design_speed, road.cross_slope,
                               d.geometry.max_superelevation, road.width / 2);
    for (int i = 0; i <= n; ++i) {
      const PolylineSample at = sample_polyline(road.centreline, arc[size_t(i)]);
      points_.push_back(at.point);
      samples_.push_back(
          {int(r), arc[size_t(i)], at.tangent, i == 0 && !road.closed, i == n && !road.closed, bank[size_t(i)]});
    }
  }
  index_ = std::make_unique<PointsKdTree>(&points_);
  add_roughness(d.geometry);
}

RoadSurface::RoadSurface(HeightFunction terrain, HeightFunction crown, const WorldGeometryParams& geometry)
    : terrain_fn_(std::move(terrain)), crown_fn_(std::move(crown)) {
  add_roughness(geometry);
}

void RoadSurface::add_roughness(const WorldGeometryParams& g) {
  // Roughness: a random-phase sum of plane waves in random directions whose amplitudes follow the
  // ISO 8608 displacement PSD over the band, in equal steps of log frequency. A profile along any
  // line then has (approximately) the class's spectrum and its RMS.
  const double psd0 = iso8608_psd(g.roughness_class);
  if (psd0 == 0) return;
  std::mt19937_64 rng(g.roughness_seed);
  std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi);
  const double n_lo = 1 / g.roughness_max_wavelength, n_hi = 1 / g.roughness_min_wavelength;
  const double log_step = std::log(n_hi / n_lo) / kRoughnessWaves;
  for (int k = 0; k < kRoughnessWaves; ++k) {
    const double n = n_lo * std::exp((k + 0.5) * log_step);  // cycles/m
    const double dn = n * log_step;                          // width of this wave's band
    const double psd = psd0 * std::pow(n / kIsoReferenceFrequency, -kIsoWaviness);
    const double direction = angle(rng);
    // A sinusoid of amplitude a has variance a^2 / 2, which must equal G(n) dn.
    waves_.push_back({2 * std::numbers::pi * n * Eigen::Vector2d(std::cos(direction), std::sin(direction)),
                      std::sqrt(2 * psd * dn), angle(rng)});
  }
}

RoadSurface::~RoadSurface() = default;

double RoadSurface::terrain(const Eigen::Vector2d& p) const {
  if (terrain_fn_) return terrain_fn_(p);
  double z = 0;
  for (const Hill& h : hills_) {
    const double r = (p - h.centre).norm();
    if (r < h.radius) z += h.height * 0.5 * (1 + std::cos(std::numbers::pi * r / h.radius));
  }
  return z;
}

double RoadSurface::roughness(const Eigen::Vector2d& p) const {
  double z = 0;
  for (const Wave& w : waves_) z += w.amplitude * std::sin(w.wavenumber.dot(p) + w.phase);
  return z;
}

// The nearest centreline sample, preferring a road the point lies beside over one whose end it lies
// beyond: where a road ends on another (a T-junction), the curb across its end belongs to the other.
RoadPoint RoadSurface::nearest_road(const Eigen::Vector2d& p) const {
  if (!index_) return {};
  std::array<uint32_t, kNearestCandidates> idx{};
  std::array<double, kNearestCandidates> d2{};
  const size_t found = index_->tree.knnSearch(p.data(), kNearestCandidates, idx.data(), d2.data());
  RoadPoint best;
  double best_score = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < found; ++k) {
    const Sample& s = samples_[idx[k]];
    const Eigen::Vector2d d = p - points_[idx[k]];
    const double along = d.dot(s.tangent);
    const bool beyond_end = (s.at_start && along < 0) || (s.at_end && along > 0);
    const double distance = std::abs(along) <= kSampleStep && !beyond_end
                                ? std::abs(lateral_offset(p, points_[idx[k]], s.tangent))
                                : std::sqrt(d2[k]);
    const double score = distance + (beyond_end ? kBeyondEndPenalty : 0.0);
    if (score >= best_score) continue;
    best_score = score;
    best.road = s.road;
    best.tangent = s.tangent;
    best.s = s.s + along;
    best.lateral = lateral_offset(p, points_[idx[k]], s.tangent);
    best.distance = distance;
  }
  return best;
}

// Each road's crown falls linearly from its centreline, or is banked through a curve; where roads meet,
// the highest of their surfaces is the pavement, so the surface stays continuous through intersections.
double RoadSurface::crown(const Eigen::Vector2d& p) const {
  if (crown_fn_) return crown_fn_(p);
  std::array<uint32_t, kNearestSamples> idx{};
  std::array<double, kNearestSamples> d2{};
  const size_t found = index_->tree.knnSearch(p.data(), kNearestSamples, idx.data(), d2.data());
  double z = -std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < found; ++k) {
    const Sample& s = samples_[idx[k]];
    const Eigen::Vector2d d = p - points_[idx[k]];
    const double along = d.dot(s.tangent);
    // Beside the sample, the offset across the road; farther along (past an open road's end), the
    // distance, on the side the point is.
    const double lateral = lateral_offset(p, points_[idx[k]], s.tangent);
    const double offset = std::abs(along) <= kSampleStep ? lateral : std::copysign(std::sqrt(d2[k]), lateral);
    z = std::max(z, banked_section(offset, cross_slope_[size_t(s.road)], s.bank));
  }
  return found ? z : 0.0;
}

GroundContact ground_contact(const Pose2d& pose, const GroundHeight& ground, double wheelbase, double track) {
  const Eigen::Vector2d forward(std::cos(pose.yaw), std::sin(pose.yaw)), left(-forward.y(), forward.x());
  const Eigen::Vector2d rear(pose.x, pose.y), front = rear + forward * wheelbase;
  const double rl = ground(rear + left * (track / 2)), rr = ground(rear - left * (track / 2));
  const double fl = ground(front + left * (track / 2)), fr = ground(front - left * (track / 2));
  return {(rl + rr) / 2, -std::atan2((fl + fr) - (rl + rr), 2 * wheelbase),  // nose up is negative about y
          std::atan2((rl + fl) - (rr + fr), 2 * track)};                     // left side up is positive
}

Eigen::Isometry3d on_ground(const Pose2d& pose, const GroundContact& contact) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translate(Eigen::Vector3d(pose.x, pose.y, contact.z));
  m.rotate(Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(contact.pitch, Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(contact.roll, Eigen::Vector3d::UnitX()));
  return m;
}

Eigen::Isometry3d rest_on_ground(const Pose2d& pose, const GroundHeight& ground, double wheelbase, double track) {
  return on_ground(pose, ground_contact(pose, ground, wheelbase, track));
}

}  // namespace lidarloop
