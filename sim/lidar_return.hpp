#pragma once
// What one laser firing reports when it meets a surface: detected or not, measured range, intensity.
#include <cstdint>
#include <optional>

#include "sim/counter_rng.hpp"
#include "sim/hdl32e.hpp"
#include "sim/materials.hpp"

namespace lidarloop {

struct LidarReturn {
  float range = 0;        // quantised, noisy; m
  uint8_t intensity = 0;  // 0-100 diffuse, 101-255 retro-reflective
};

class ReturnModel {
 public:
  explicit ReturnModel(const Hdl32eConfig& config);

  // `cos_incidence` between the beam and the surface normal; draws 3k..3k+2 of `rng` are used.
  std::optional<LidarReturn> operator()(const Material& material, double range, double cos_incidence, int ring,
                                        const CounterRng& rng, uint64_t k) const;
  double laser_gain(int ring) const { return gain_[ring]; }
  double laser_range_bias(int ring) const { return range_bias_[ring]; }
  double laser_intensity_offset(int ring) const { return intensity_offset_[ring]; }
  // Received power up to a constant, reflectivity * cos(incidence)^exponent / range^2: how strongly a
  // surface contributes to an echo (mixed returns weigh the surfaces in a beam's spot by it).
  double signal(const Material& material, double range, double cos_incidence) const;

 private:
  Hdl32eConfig c_;
  double min_power_;  // reflectivity / range^2 of a target detected half the time
  double min_cos_incidence_;
  double sure_miss_, sure_hit_;  // detection margins beyond which no random draw is needed
  std::array<double, kHdl32eLasers> gain_, range_bias_, intensity_offset_;
};

}  // namespace lidarloop
