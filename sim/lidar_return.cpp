#include "sim/lidar_return.hpp"

#include <algorithm>
#include <cmath>

namespace lidarloop {

ReturnModel::ReturnModel(const Hdl32eConfig& config)
    : c_(config),
      min_power_(config.dark_target_reflectivity / (config.dark_target_range_m * config.dark_target_range_m)),
      min_cos_incidence_(std::cos(config.max_incidence_deg * M_PI / 180)) {
  // Per-laser gains are a property of the unit, like a real sensor's calibration table.
  const CounterRng unit(config.unit_serial, 0x6761696eULL);
  for (int ring = 0; ring < kHdl32eLasers; ++ring)
    gain_[ring] = 1.0 + config.laser_gain_spread * (2.0 * unit.uniform(uint64_t(ring)) - 1.0);
}

std::optional<LidarReturn> ReturnModel::operator()(const Material& material, double range, double cos_incidence,
                                                   int ring, const CounterRng& rng, uint64_t k) const {
  if (cos_incidence < min_cos_incidence_) return std::nullopt;  // grazing: the spot smears out
  // Retro-reflectors send light back whatever the angle: treat them as very bright for detection.
  const double reflectivity = material.retro ? 100.0 * material.reflectivity : material.reflectivity;
  const double power = reflectivity * std::pow(cos_incidence, c_.detection_incidence_exponent) / (range * range);
  if (c_.detection_softness > 0) {
    const double p_detect = 1.0 / (1.0 + std::exp(-std::log(power / min_power_) / c_.detection_softness));
    if (rng.uniform(3 * k) >= p_detect) return std::nullopt;
  } else if (power < min_power_) {
    return std::nullopt;
  }

  double measured = range + c_.range_noise_m * rng.normal(3 * k + 1);
  if (c_.range_resolution_m > 0) measured = std::round(measured / c_.range_resolution_m) * c_.range_resolution_m;
  if (measured < c_.min_range_m || measured > c_.max_range_m) return std::nullopt;

  const double falloff =
      std::pow(std::min(1.0, c_.intensity_reference_range_m / range), c_.intensity_range_exponent);
  const double response = std::pow(cos_incidence, c_.intensity_incidence_exponent) * gain_[ring] * falloff;
  const double noise = c_.intensity_noise * rng.normal(3 * k + 2);
  double intensity = material.retro ? 101.0 + 154.0 * material.reflectivity * response + noise
                                    : 100.0 * material.reflectivity * response + noise;
  intensity = material.retro ? std::clamp(intensity, 101.0, 255.0) : std::clamp(intensity, 0.0, 100.0);
  return LidarReturn{static_cast<float>(measured), static_cast<uint8_t>(std::lround(intensity))};
}

}  // namespace lidarloop
