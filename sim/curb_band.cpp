#include "sim/curb_band.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/points_kd_tree.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {
namespace {

constexpr double kOnEdgeTolerance = 0.3;  // m: a curb point this close to w/2 from the centreline runs
                                          // along the road (not round an intersection's corner)
constexpr double kMaxMiter = 2.0;         // offsets at corners sharper than 60 degrees are clipped
constexpr int kFaceSamples = 3;           // cross-section points up a curved face
constexpr double kMinVariationWavelength = 20, kMaxVariationWavelength = 80;  // m, as-built reveal
constexpr int kVariationWaves = 3;

Eigen::Vector2d right_normal(const Eigen::Vector2d& t) { return {t.y(), -t.x()}; }

// Smooth variation of the curb reveal along a road: a few long sinusoids, within +-amplitude.
struct RevealVariation {
  struct Wave {
    double wavenumber, phase;
  };
  std::vector<Wave> waves;
  double amplitude = 0;

  RevealVariation(uint64_t seed, double amplitude_m) : amplitude(amplitude_m) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> wavelength(kMinVariationWavelength, kMaxVariationWavelength);
    std::uniform_real_distribution<double> phase(0, 2 * std::numbers::pi);
    for (int k = 0; k < kVariationWaves; ++k) waves.push_back({2 * std::numbers::pi / wavelength(rng), phase(rng)});
  }
  double operator()(double s) const {
    double v = 0;
    for (const Wave& w : waves) v += std::sin(w.wavenumber * s + w.phase);
    return amplitude * v / kVariationWaves;
  }
};

}  // namespace

std::vector<CurbCutSpan> curb_cuts_of(const WorldDescription& d, int road, RoadSide side) {
  const RoadSpec& r = d.roads[size_t(road)];
  std::vector<CurbCutSpan> out;
  for (const auto& c : d.curb_cuts)
    if (c.road == r.name && c.side == side) out.push_back({c.at - c.length / 2, c.at + c.length / 2, c.kind});
  for (const auto& c : d.crosswalks)
    if (d.geometry.crosswalk_ramps && c.road == r.name)
      out.push_back({c.at - c.width / 2, c.at + c.width / 2, CurbCut::ramp});
  if (r.driveway_spacing > 0) {
    const double length = polyline_length(r.centreline);
    for (double s = r.driveway_spacing / 2; s + r.driveway_width / 2 < length; s += r.driveway_spacing) {
      const CurbCutSpan cut{s - r.driveway_width / 2, s + r.driveway_width / 2, CurbCut::driveway};
      // A driveway does not run into a crosswalk's ramp or another cut.
      bool clear = true;
      for (const CurbCutSpan& other : out) clear = clear && (cut.to < other.from || cut.from > other.to);
      if (clear) out.push_back(cut);
    }
  }
  return out;
}

// Face shapes. Vertical: AASHTO's vertical curb. Sloped: a 1:1 batter (an assumption within AASHTO's
// mountable curbs, which only bound the height). Rolled: an S-shaped face over twice its height, as
// the common "roll curb and gutter" standard drawings show (an assumption; no national standard).
double face_run(CurbProfile profile, double height) {
  switch (profile) {
    case CurbProfile::vertical:
      return 0;
    case CurbProfile::sloped:
      return height;
    case CurbProfile::rolled:
      return 2 * height;
  }
  return 0;
}

double face_rise(CurbProfile profile, double u) {
  u = std::clamp(u, 0.0, 1.0);
  return profile == CurbProfile::rolled ? 0.5 * (1 - std::cos(std::numbers::pi * u)) : u;
}

const char* curb_profile_name(CurbProfile profile) {
  switch (profile) {
    case CurbProfile::vertical:
      return "vertical";
    case CurbProfile::sloped:
      return "sloped";
    case CurbProfile::rolled:
      return "rolled";
  }
  return "?";
}

const char* curb_cut_name(CurbCut cut) {
  switch (cut) {
    case CurbCut::driveway:
      return "driveway";
    case CurbCut::ramp:
      return "ramp";
    case CurbCut::flush:
      return "flush";
  }
  return "?";
}

CurbBandWidths curb_band_widths(const WorldDescription& d) {
  CurbBandWidths w;
  double run = 0;
  for (const auto& r : d.roads) {
    w.inner = std::max(w.inner, r.gutter_width);
    run = std::max(run, face_run(r.curb_profile, r.curb_height + r.curb_height_variation));
  }
  w.outer = run + d.geometry.curb_top_width;
  return w;
}

std::vector<std::vector<CurbStation>> curb_stations(const std::vector<Polyline2d>& rings, const WorldDescription& d,
                                                    const RoadSurface& surface, double step) {
  std::vector<RevealVariation> variation;
  std::vector<std::array<std::vector<CurbCutSpan>, 2>> cuts;  // per road: right, left
  for (size_t r = 0; r < d.roads.size(); ++r) {
    variation.emplace_back(d.geometry.roughness_seed * d.roads.size() + r, d.roads[r].curb_height_variation);
    cuts.push_back({curb_cuts_of(d, int(r), RoadSide::right), curb_cuts_of(d, int(r), RoadSide::left)});
  }
  std::vector<std::vector<CurbStation>> out;
  for (const Polyline2d& closed : rings) {
    Polyline2d ring(closed.begin(), closed.end() - 1);  // without the repeated first point
    const size_t n = ring.size();
    if (n < 3) continue;
    std::vector<CurbStation> stations;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d &prev = ring[(i + n - 1) % n], &a = ring[i], &b = ring[(i + 1) % n];
      const Eigen::Vector2d n_in = right_normal((a - prev).normalized()), n_out = right_normal((b - a).normalized());
      const int pieces = std::max(1, int(std::ceil((b - a).norm() / step)));
      for (int k = 0; k < pieces; ++k) {
        CurbStation c;
        c.point = a + (b - a) * (double(k) / pieces);
        c.normal = k == 0 ? (n_in + n_out).normalized() : n_out;
        c.miter = k == 0 ? std::min(kMaxMiter, 1 / std::max(1 / kMaxMiter, c.normal.dot(n_out))) : 1.0;
        stations.push_back(c);
      }
    }
    for (CurbStation& c : stations) {
      const RoadPoint at = surface.nearest_road(c.point);
      const RoadSpec& road = d.roads[size_t(at.road)];
      c.road = at.road;
      c.s = at.s;
      c.profile = road.curb_profile;
      c.nominal_height = road.curb_height + variation[size_t(at.road)](at.s);
      c.height = c.nominal_height;
      c.gutter_width = road.gutter_width;
      c.gutter_slope = road.gutter_slope;
      c.sidewalk_width = road.sidewalk_width;
      c.terrain_z = surface.terrain(c.point);
      if (std::abs(at.distance - road.width / 2) < kOnEdgeTolerance) {
        const double flare = c.nominal_height / d.geometry.flare_slope;
        for (const CurbCutSpan& cut : cuts[size_t(at.road)][at.lateral > 0 ? 1 : 0]) {
          const double outside = std::max({cut.from - at.s, at.s - cut.to, 0.0});
          c.height = std::min(c.height, c.nominal_height * std::min(1.0, outside / flare));
          if (outside == 0) c.cut = cut.kind;
        }
      }
      if (c.gutter_width > 0) {
        const Eigen::Vector2d lip = c.point - c.normal * (c.miter * c.gutter_width);
        c.bottom_z = surface.carriageway(lip) - c.gutter_slope * c.gutter_width;
      } else {
        c.bottom_z = surface.carriageway(c.point);
      }
    }
    out.push_back(std::move(stations));
  }
  return out;
}

Polyline2d offset_ring(const std::vector<CurbStation>& ring, double offset) {
  Polyline2d line;
  for (const CurbStation& c : ring) line.push_back(c.point + c.normal * (c.miter * offset));
  if (!line.empty()) line.push_back(line.front());
  return line;
}

RaisedGround::RaisedGround(std::vector<std::vector<CurbStation>> rings, std::shared_ptr<const RoadSurface> surface,
                           const WorldGeometryParams& geometry, double band_outer)
    : rings_(std::move(rings)),
      surface_(std::move(surface)),
      sidewalk_cross_slope_(geometry.sidewalk_cross_slope),
      ramp_slope_(geometry.ramp_slope),
      band_outer_(band_outer) {
  for (const auto& ring : rings_)
    for (const CurbStation& c : ring) {
      flat_.push_back(&c);
      points_.push_back(c.point);
    }
  index_ = std::make_unique<PointsKdTree>(&points_);
}

RaisedGround::~RaisedGround() = default;

double RaisedGround::from_station(const CurbStation& c, const Eigen::Vector2d& p) const {
  const double behind = std::max(0.0, (p - c.point).norm() - band_outer_);
  const double top = c.bottom_z + c.height, uncut = c.bottom_z + c.nominal_height;
  // Behind a cut the ramp climbs at its own slope until it meets the sidewalk, which rises away from
  // the curb at its cross-slope.
  const double sidewalk = uncut + sidewalk_cross_slope_ * std::min(behind, c.sidewalk_width);
  return std::min(sidewalk, top + ramp_slope_ * behind) + surface_->terrain(p) - c.terrain_z;
}

// Inverse-distance blend of the two nearest cross-sections, so heights change smoothly along a curb.
double RaisedGround::operator()(const Eigen::Vector2d& p) const {
  if (points_.empty()) return surface_->terrain(p);
  std::array<uint32_t, 2> idx{};
  std::array<double, 2> d2{};
  const size_t found = index_->tree.knnSearch(p.data(), 2, idx.data(), d2.data());
  double sum = 0, weights = 0;
  for (size_t k = 0; k < found; ++k) {
    const double w = 1 / (std::sqrt(d2[k]) + 1e-3);
    sum += w * from_station(*flat_[idx[k]], p);
    weights += w;
  }
  return sum / weights;
}

void mesh_curb_band(const RaisedGround& raised, const RoadSurface& surface, CurbBandWidths widths, MaterialId pavement,
                    MaterialId concrete, TriangleMesh& mesh) {
  constexpr int kPoints = 4 + kFaceSamples;  // inner edge, gutter lip, foot, face samples, outer edge
  for (const auto& ring : raised.rings()) {
    const auto base = static_cast<uint32_t>(mesh.vertices.size());
    for (const CurbStation& c : ring) {
      auto at = [&](double o) { return Eigen::Vector2d(c.point + c.normal * (c.miter * o)); };
      auto add = [&](const Eigen::Vector2d& xy, double z) {
        mesh.vertices.emplace_back(float(xy.x()), float(xy.y()), float(z));
      };
      add(at(-widths.inner), surface.carriageway(at(-widths.inner)));
      add(at(-c.gutter_width), c.gutter_width > 0 ? surface.carriageway(at(-c.gutter_width)) : c.bottom_z);
      add(c.point, c.bottom_z);
      const double run = face_run(c.profile, c.height);
      for (int j = 1; j <= kFaceSamples; ++j) {
        const double u = double(j) / kFaceSamples;
        add(at(run * u), c.bottom_z + c.height * face_rise(c.profile, u));
      }
      add(at(widths.outer), raised(at(widths.outer)));
    }
    const auto n = uint32_t(ring.size());
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t a = base + i * kPoints, b = base + ((i + 1) % n) * kPoints;
      for (uint32_t k = 0; k + 1 < kPoints; ++k) {
        const MaterialId m = k == 0 ? pavement : concrete;
        mesh.add_triangle(a + k, a + k + 1, b + k + 1, m);
        mesh.add_triangle(a + k, b + k + 1, b + k, m);
      }
    }
  }
}

void curb_lines(const std::vector<std::vector<CurbStation>>& rings, std::vector<Polyline2d>& lines,
                std::vector<std::string>& kinds) {
  for (const auto& ring : rings) {
    const size_t n = ring.size();
    auto kind = [&](size_t i) -> std::string {
      const CurbStation& c = ring[i % n];
      return c.cut ? curb_cut_name(*c.cut) : curb_profile_name(c.profile);
    };
    size_t start = 0;
    while (start < n && kind(start) == kind(start + n - 1)) ++start;
    if (start == n) {  // one kind all round: a closed line
      Polyline2d line;
      for (const auto& c : ring) line.push_back(c.point);
      line.push_back(ring.front().point);
      lines.push_back(std::move(line));
      kinds.push_back(kind(0));
      continue;
    }
    Polyline2d line{ring[start].point};
    for (size_t k = 1; k <= n; ++k) {
      const size_t i = start + k;
      line.push_back(ring[i % n].point);  // a line ends on the first point of the next, so they join
      if (k == n || kind(i) != kind(i - 1)) {
        lines.push_back(std::move(line));
        kinds.push_back(kind(i - 1));
        line = {ring[i % n].point};
      }
    }
  }
}

}  // namespace lidarloop
