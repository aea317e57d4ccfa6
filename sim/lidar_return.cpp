#include "sim/lidar_return.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop {

// x^e for x in [0, 1]. The model runs once per return, and its default exponents (0.25, 0.5, 1) have
// exact forms far cheaper than std::pow.
static double power(double x, double e) {
  if (e == 0.5) return std::sqrt(x);
  if (e == 1.0) return x;
  if (e == 0.25) return std::sqrt(std::sqrt(x));
  if (e == 0.0) return 1.0;
  return std::pow(x, e);
}

ReturnModel::ReturnModel(const Hdl32eConfig& config)
    : c_(config),
      min_power_(config.dark_target_reflectivity / (config.dark_target_range_m * config.dark_target_range_m)),
      min_cos_incidence_(std::cos(config.max_incidence_deg * M_PI / 180)),
      // Where the logistic detection ramp is within 1e-9 of 0 or 1 (a step when softness is 0).
      sure_miss_(std::exp(-20.7 * config.detection_softness)),
      sure_hit_(std::exp(20.7 * config.detection_softness)) {
  // Per-laser gains are a property of the unit, like a real sensor's calibration table.
  const CounterRng unit(config.unit_serial, 0x6761696eULL);
  // Range biases and intensity offsets come from streams of their own, so the gains stay those of
  // the same serial before these faults were modelled.
  const CounterRng biases(config.unit_serial, 0x72626961ULL), offsets(config.unit_serial, 0x696f6666ULL);
  for (int ring = 0; ring < kHdl32eLasers; ++ring) {
    gain_[ring] = 1.0 + config.laser_gain_spread * (2.0 * unit.uniform(uint64_t(ring)) - 1.0);
    range_bias_[ring] = config.laser_range_bias_sigma_m * biases.normal(uint64_t(ring));
    intensity_offset_[ring] = config.laser_intensity_offset_sigma * offsets.normal(uint64_t(ring));
  }
}

double ReturnModel::signal(const Material& material, double range, double cos_incidence) const {
  const double reflectivity = material.retro ? 100.0 * material.reflectivity : material.reflectivity;
  return reflectivity * power(cos_incidence, c_.detection_incidence_exponent) / (range * range);
}

std::optional<LidarReturn> ReturnModel::operator()(const Material& material, double range, double cos_incidence,
                                                   int ring, const CounterRng& rng, uint64_t k) const {
  if (cos_incidence < min_cos_incidence_) return std::nullopt;  // grazing: the spot smears out
  // Retro-reflectors send light back whatever the angle: treat them as very bright for detection.
  const double reflectivity = material.retro ? 100.0 * material.reflectivity : material.reflectivity;
  const double margin = reflectivity * power(cos_incidence, c_.detection_incidence_exponent) /
                        (range * range * min_power_);  // received power over the detection threshold
  // Detection probability 1 / (1 + margin^(-1/softness)): a logistic ramp in log power. Far above or
  // below the ramp the answer is certain and needs no draw.
  if (margin < sure_miss_) return std::nullopt;
  if (margin < sure_hit_) {
    const double p_detect = 1.0 / (1.0 + std::pow(margin, -1.0 / c_.detection_softness));
    if (rng.uniform(3 * k) >= p_detect) return std::nullopt;
  }

  // The laser's range bias is part of what it measures: the quantisation and range limits apply after it.
  double measured = range + range_bias_[ring] + c_.range_noise_m * rng.normal(3 * k + 1);
  if (c_.range_resolution_m > 0) measured = std::round(measured / c_.range_resolution_m) * c_.range_resolution_m;
  if (measured < c_.min_range_m || measured > c_.max_range_m) return std::nullopt;

  const double falloff = power(std::min(1.0, c_.intensity_reference_range_m / range), c_.intensity_range_exponent);
  const double response = power(cos_incidence, c_.intensity_incidence_exponent) * gain_[ring] * falloff;
  const double noise = c_.intensity_noise * rng.normal(3 * k + 2) + intensity_offset_[ring];
  double intensity = material.retro ? 101.0 + 154.0 * material.reflectivity * response + noise
                                    : 100.0 * material.reflectivity * response + noise;
  intensity = material.retro ? std::clamp(intensity, 101.0, 255.0) : std::clamp(intensity, 0.0, 100.0);
  return LidarReturn{static_cast<float>(measured), static_cast<uint8_t>(std::lround(intensity))};
}

}  // namespace lidarloop
