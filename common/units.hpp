#pragma once
// Unit conversions. Code works in SI (m, s, rad); degrees appear only in files and flags for people,
// and clocks are integer nanoseconds.
#include <cstdint>
#include <numbers>

namespace lidarloop {

inline constexpr double kDeg = std::numbers::pi / 180.0;        // rad per degree: 30 * kDeg
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;  // degrees = rad * kDegPerRad
inline constexpr int64_t kNsPerS = 1'000'000'000;
inline constexpr double kGravity = 9.80665;  // m/s^2, standard gravity (ISO 80000-3)

inline constexpr double ns_to_s(int64_t ns) { return double(ns) / double(kNsPerS); }

}  // namespace lidarloop
