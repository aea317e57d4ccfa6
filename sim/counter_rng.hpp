#pragma once
// Counter-based random numbers: draw k of stream `key` is a pure function of (key, k), so a ray's
// noise does not depend on which thread cast it or in what order. SplitMix64 finaliser as the hash.
#include <cmath>
#include <cstdint>

namespace lidarloop {

constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class CounterRng {
 public:
  constexpr CounterRng(uint64_t seed, uint64_t stream) : key_(mix64(seed ^ mix64(stream))) {}
  // Uniform in [0, 1).
  double uniform(uint64_t counter) const { return double(mix64(key_ + counter) >> 11) * 0x1.0p-53; }
  // Zero-mean, unit-variance and nearly normal (sum of four uniforms, Irwin-Hall): cheap, and the
  // tails stop at 3.46 sigma, which suits sensor noise models.
  double normal(uint64_t counter) const {
    const uint64_t bits = mix64(key_ + counter);
    double sum = 0;
    for (int k = 0; k < 4; ++k) sum += double((bits >> (16 * k)) & 0xffff) * (1.0 / 65536.0);
    return (sum - 2.0 + 2.0 / 65536.0) * 1.7320508075688772;  // variance of the sum is 4/12
  }

 private:
  uint64_t key_;
};

}  // namespace lidarloop
