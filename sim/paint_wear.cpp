#include "sim/paint_wear.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace lidarloop {
namespace {

// One stream per kind of draw, so that no draw depends on another's (e.g. the scatter on the wear).
constexpr uint64_t kRetroStream = 0x7061696e7401, kScatterStream = 0x7061696e7402, kWearStream = 0x7061696e7403,
                   kChangeStream = 0x7061696e7404;
// A variant's reflectivity is rounded to this step (0.1 intensity count at normal incidence): markings
// of nearly the same reflectivity share a material, so the table stays small on large worlds.
constexpr double kReflectivityStep = 1e-3;
constexpr double kCentimetre = 100.0;  // places are keyed to the centimetre

}  // namespace

std::string PaintConfig::describe_survey() const {
  if (!varied) return "";
  std::ostringstream s;
  s.precision(17);
  s << "paint: retro_mean=" << retro_mean_mcd << " retro_sigma=" << retro_sigma_mcd << " retro_min=" << retro_min_mcd
    << " material_retro=" << material_retro_mcd << " r2=" << intensity_r2 << " segment=" << segment_m
    << " worn=" << worn_fraction << " seed=" << seed;
  return s.str();
}

PaintConfig paint_config_for(Realism realism) {
  PaintConfig c;
  switch (realism) {
    case Realism::ideal:
      c.varied = false;  // uniform, new paint
      break;
    case Realism::typical:
      break;  // the sourced campus figures: PaintConfig's defaults
    case Realism::harsh:
      // Markings near the end of their life: R_L about the maintained minimums (FHWA 50-100, middle 75,
      // spread so that 50 is 1 sigma below and 100 one above: assumption), floored at the lower
      // minimum, 50; a third of the area worn, and twice the typical changes since the survey
      // (assumptions).
      c.varied = true;
      c.retro_mean_mcd = 75;
      c.retro_sigma_mcd = 25;
      c.retro_min_mcd = 50;
      c.worn_fraction = 0.30;
      c.faded_fraction = 0.20;
      c.repainted_fraction = 0.10;
      break;
  }
  return c;
}

void read_paint_config(const YamlReader& y, const YAML::Node& n, PaintConfig& c) {
  // Ranges that catch typos and units (a retroreflectivity in cd rather than mcd), not physical limits.
  constexpr double kMaxRetro = 5000, kMaxSegment = 1000;
  YamlMap(y, n, "paint")
      .boolean("varied", c.varied)
      .number("retro_mean_mcd", c.retro_mean_mcd, 0.0, kMaxRetro)
      .number("retro_sigma_mcd", c.retro_sigma_mcd, 0.0, kMaxRetro)
      .number("retro_min_mcd", c.retro_min_mcd, 0.0, kMaxRetro)
      .number("material_retro_mcd", c.material_retro_mcd, 1.0, kMaxRetro)
      .number("intensity_r2", c.intensity_r2, 0.01, 1.0)
      .number("segment_m", c.segment_m, 0.1, kMaxSegment)
      .number("worn_fraction", c.worn_fraction, 0.0, 1.0)
      .number("faded_fraction", c.faded_fraction, 0.0, 1.0)
      .number("fade_factor", c.fade_factor, 0.0, 1.0)
      .number("repainted_fraction", c.repainted_fraction, 0.0, 1.0)
      .number("repaint_mcd", c.repaint_mcd, 0.0, kMaxRetro)
      .integer("seed", c.seed, 0, uint64_t(1) << 62)
      .done();
  if (c.faded_fraction + c.repainted_fraction > 1.0) y.fail(n, "paint: faded_fraction + repainted_fraction exceeds 1");
}

PaintRng::PaintRng(uint64_t seed)
    : retro(seed, kRetroStream), scatter(seed, kScatterStream), wear(seed, kWearStream), change(seed, kChangeStream) {}

uint64_t marking_key(const Eigen::Vector2d& place, uint64_t index) {
  const auto x = uint64_t(int64_t(std::llround(place.x() * kCentimetre)));
  const auto y = uint64_t(int64_t(std::llround(place.y() * kCentimetre)));
  return mix64(mix64(mix64(x) ^ y) ^ index);
}

MarkingLook draw_marking(const PaintConfig& c, PaintDay day, const PaintRng& rng, double material_reflectivity,
                         uint64_t key) {
  MarkingLook m;
  m.retro_mcd = std::max(c.retro_min_mcd, c.retro_mean_mcd + c.retro_sigma_mcd * rng.retro.normal(key));
  if (day == PaintDay::drive) {
    const double u = rng.change.uniform(key);
    if (u < c.faded_fraction) {
      m.retro_mcd *= c.fade_factor;
    } else if (u < c.faded_fraction + c.repainted_fraction) {
      m.retro_mcd = c.repaint_mcd;
      m.repainted = true;
    }
  }
  // Reflectivity in proportion to R_L, with the scatter that leaves the wanted share of its variance
  // explained: R^2 = var(kR) / (var(kR) + s^2), so s = k sigma_R sqrt((1 - R^2) / R^2).
  const double k = material_reflectivity / c.material_retro_mcd;
  const double scatter = k * c.retro_sigma_mcd * std::sqrt((1 - c.intensity_r2) / c.intensity_r2);
  m.reflectivity = std::clamp(k * m.retro_mcd + scatter * rng.scatter.normal(key), 0.0, 1.0);
  return m;
}

bool worn_piece(const PaintConfig& c, const PaintRng& rng, uint64_t key) {
  return c.worn_fraction > 0 && rng.wear.uniform(key) < c.worn_fraction;
}

MarkingPainter::MarkingPainter(const std::optional<PaintConditions>& conditions, const MaterialTable& materials)
    : conditions_(conditions && conditions->config.varied ? conditions : std::nullopt),
      rng_(conditions ? conditions->config.seed : 0),
      materials_(materials) {}

MaterialId MarkingPainter::marking(MaterialId base, uint64_t key, bool& fresh) {
  fresh = false;
  if (!conditions_) return base;
  const Material& material = materials_[base];
  const MarkingLook look = draw_marking(conditions_->config, conditions_->day, rng_, material.reflectivity, key);
  fresh = look.repainted;
  const int step = int(std::lround(look.reflectivity / kReflectivityStep));
  const auto [it, added] = variant_ids_.try_emplace({base, step}, MaterialId(materials_.size() + variants_.size()));
  if (added) {
    Material v = material;  // same name: the weather and the puddles treat it as the paint it is
    v.reflectivity = step * kReflectivityStep;
    variants_.push_back(v);
  }
  return it->second;
}

bool MarkingPainter::worn(const Eigen::Vector2d& centre, bool fresh) const {
  return conditions_ && !fresh && worn_piece(conditions_->config, rng_, marking_key(centre));
}

}  // namespace lidarloop
