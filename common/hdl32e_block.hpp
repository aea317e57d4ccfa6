#pragma once
// One HDL-32E firing cycle as the sensor reports it on the wire (one data block of a UDP packet),
// and the point a Velodyne driver makes of one of its returns. The simulator (sim/lidar_scanner.hpp)
// builds its reported points with hdl32e_point() from exactly these quantised values, so a driver
// decoding our packets (logs/hdl32e_packets.hpp) gets the same cloud as the PointCloud2 we log.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace lidarloop {

inline constexpr int kHdl32eChannels = 32;
// Azimuth in hundredths of a degree, [0, 36000) (HDL-32E manual, data packet format; the ROS
// driver's rawdata.h ROTATION_RESOLUTION 0.01 and ROTATION_MAX_UNITS 36000).
inline constexpr double kHdl32eAzimuthUnitDeg = 0.01;
inline constexpr int kHdl32eAzimuthUnits = 36000;
// Distance unit 2 mm (HDL-32E manual; distance_resolution 0.002 in @foxglove/velodyne-cloud's
// 32db.json, DISTANCE_RESOLUTION in the ROS driver's rawdata.h).
inline constexpr double kHdl32eDistanceUnitM = 0.002;

struct Hdl32eBlock {
  uint16_t azimuth = 0;                              // of the cycle's first firing, 0.01 deg
  std::array<uint16_t, kHdl32eChannels> distance{};  // per channel (firing slot), 2 mm; 0 = no return
  std::array<uint8_t, kHdl32eChannels> intensity{};  // per channel
};

// One revolution's firing cycles, each one block, on the sensor's (GPS-disciplined) clock: cycle k
// starts at start_ns + k * cycle_period_ns.
struct Hdl32eRotation {
  int64_t start_ns = 0;
  int64_t cycle_period_ns = 0;
  std::vector<Hdl32eBlock> blocks;
};

// The azimuth the encoder reports for a head yaw in the sensor frame (x forward, y left, rad). The
// drivers put a point at (cos a, -sin a) for azimuth a (below): the azimuth grows clockwise from
// the x axis, so it is minus the yaw.
inline uint16_t hdl32e_azimuth(double yaw_rad) {
  const double units = std::round(-yaw_rad * 180.0 / M_PI / kHdl32eAzimuthUnitDeg);
  const double wrapped = units - std::floor(units / kHdl32eAzimuthUnits) * kHdl32eAzimuthUnits;
  return uint16_t(int(wrapped) % kHdl32eAzimuthUnits);
}

// A return where the ROS velodyne driver (velodyne_pointcloud rawdata.cpp, RawData::unpack, which
// handles the HDL-32E) and @foxglove/velodyne-cloud (Transformer._unpackGeneric, computePosition) put
// it, with the HDL-32E calibration (32db.yaml / 32db.json: no rotational, distance or offset
// corrections): the block's azimuth for every channel (no interpolation within the block), the
// channel's vertical angle, distance = units * 2 mm, then "standard ROS coordinate system":
//   x = d cos(v) cos(a),  y = -d cos(v) sin(a),  z = d sin(v).
struct Hdl32ePoint {
  float x, y, z;
};
// The azimuth's cosine and sine (the drivers' cos_rot_table / sin_rot_table).
struct Hdl32eRotation2d {
  double cos, sin;
};
inline Hdl32eRotation2d hdl32e_rotation(uint16_t azimuth) {
  const double a = double(azimuth) * kHdl32eAzimuthUnitDeg * M_PI / 180.0;
  return {std::cos(a), std::sin(a)};
}
inline Hdl32ePoint hdl32e_point(Hdl32eRotation2d rotation, double cos_vertical, double sin_vertical,
                                uint16_t distance) {
  const double d = double(distance) * kHdl32eDistanceUnitM, xy = d * cos_vertical;
  return {float(xy * rotation.cos), float(-xy * rotation.sin), float(d * sin_vertical)};
}
inline Hdl32ePoint hdl32e_point(uint16_t azimuth, double cos_vertical, double sin_vertical, uint16_t distance) {
  return hdl32e_point(hdl32e_rotation(azimuth), cos_vertical, sin_vertical, distance);
}

}  // namespace lidarloop
