#include "logs/hdl32e_packets.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {

constexpr size_t kBlockSize = 100;          // flag, azimuth, 32 x 3 bytes
constexpr size_t kTimestampOffset = 1200;   // after the 12 blocks
constexpr size_t kReturnModeOffset = 1204;  // the two factory bytes
constexpr size_t kProductIdOffset = 1205;
constexpr uint8_t kFlag0 = 0xFF, kFlag1 = 0xEE;  // upper bank: uint16 0xEEFF on the wire, little endian
constexpr int64_t kUsPerHour = 3'600'000'000;
// Position packet (VeloView vtkVelodyneHDLPositionReader; ros-drivers/velodyne gps_imu branch,
// VelodynePositioningPacketRaw): the timestamp after 14 + 3 x 8 + 160 bytes, the sentence 4 bytes on.
constexpr size_t kPositionTimestampOffset = 198, kNmeaOffset = 206;
constexpr double kKnotsPerMps = 3600.0 / 1852.0;

void put16(uint8_t* p, uint16_t v) { p[0] = uint8_t(v), p[1] = uint8_t(v >> 8); }
void put32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
uint16_t get16(const uint8_t* p) { return uint16_t(p[0] | p[1] << 8); }
uint32_t get32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

int64_t floor_div(int64_t a, int64_t b) { return a / b - (a % b != 0 && (a < 0) != (b < 0)); }

// "ddmm.mmmmm" (digits 2) or "dddmm.mmmmm" (digits 3) and the hemisphere letter of an angle.
std::string nmea_angle(double deg, int digits, char positive, char negative) {
  const double a = std::abs(deg);
  int whole = int(a);
  double minutes = (a - whole) * 60.0;
  if (std::round(minutes * 1e5) >= 60.0 * 1e5) ++whole, minutes = 0;  // 59.999996' rounds up a degree
  char text[32];
  std::snprintf(text, sizeof text, "%0*d%08.5f,%c", digits, whole, minutes, deg < 0 ? negative : positive);
  return text;
}

}  // namespace

std::array<uint8_t, kHdl32eDataPacketSize> encode_hdl32e_packet(const Hdl32eDataPacket& packet) {
  std::array<uint8_t, kHdl32eDataPacketSize> out{};
  for (size_t b = 0; b < packet.blocks.size(); ++b) {
    uint8_t* p = out.data() + b * kBlockSize;
    const Hdl32eBlock& block = packet.blocks[b];
    p[0] = kFlag0, p[1] = kFlag1;
    put16(p + 2, block.azimuth);
    for (size_t j = 0; j < size_t(kHdl32eChannels); ++j) {
      put16(p + 4 + 3 * j, block.distance[j]);
      p[4 + 3 * j + 2] = block.intensity[j];
    }
  }
  put32(out.data() + kTimestampOffset, packet.usec_past_hour);
  out[kReturnModeOffset] = packet.return_mode;
  out[kProductIdOffset] = kHdl32eProductId;
  return out;
}

Hdl32eDataPacket decode_hdl32e_packet(std::span<const uint8_t> bytes, const std::string& context) {
  auto fail = [&](const std::string& problem) { throw InputError(context + ": " + problem); };
  if (bytes.size() != kHdl32eDataPacketSize)
    fail(std::to_string(bytes.size()) + " bytes, a data packet has " + std::to_string(kHdl32eDataPacketSize));
  if (bytes[kProductIdOffset] != kHdl32eProductId)
    fail("product id " + std::to_string(bytes[kProductIdOffset]) + " is not the HDL-32E's (33)");
  Hdl32eDataPacket packet;
  packet.return_mode = bytes[kReturnModeOffset];
  if (packet.return_mode != kStrongestReturn && packet.return_mode != kLastReturn)
    fail("return mode " + std::to_string(packet.return_mode) + " is not single return (55 or 56)");
  packet.usec_past_hour = get32(&bytes[kTimestampOffset]);
  if (packet.usec_past_hour >= kUsPerHour)
    fail("timestamp " + std::to_string(packet.usec_past_hour) + " us is past the hour");
  for (size_t b = 0; b < packet.blocks.size(); ++b) {
    const uint8_t* p = &bytes[b * kBlockSize];
    if (p[0] != kFlag0 || p[1] != kFlag1) fail("block " + std::to_string(b) + " has no 0xFF 0xEE flag");
    Hdl32eBlock& block = packet.blocks[b];
    block.azimuth = get16(p + 2);
    if (block.azimuth >= kHdl32eAzimuthUnits)
      fail("block " + std::to_string(b) + " azimuth " + std::to_string(block.azimuth) + " is not below 36000");
    for (size_t j = 0; j < size_t(kHdl32eChannels); ++j) {
      block.distance[j] = get16(p + 4 + 3 * j);
      block.intensity[j] = p[4 + 3 * j + 2];
    }
  }
  return packet;
}

uint32_t usec_past_hour(int64_t t_ns) {
  const int64_t us = floor_div(t_ns, 1000);
  return uint32_t(us - floor_div(us, kUsPerHour) * kUsPerHour);
}

std::vector<ros2::VelodynePacket> hdl32e_data_packets(const Hdl32eRotation& rotation) {
  const auto& blocks = rotation.blocks;
  std::vector<ros2::VelodynePacket> packets;
  for (size_t first = 0; first < blocks.size(); first += kHdl32eBlocksPerPacket) {
    Hdl32eDataPacket packet;
    for (size_t k = 0; k < size_t(kHdl32eBlocksPerPacket); ++k) {
      if (first + k < blocks.size()) {
        packet.blocks[k] = blocks[first + k];
        continue;
      }
      // Padding after the revolution's last cycle: no returns, the head turning on by the last step.
      const uint16_t last = packet.blocks[k - 1].azimuth;
      const uint16_t before = k >= 2               ? packet.blocks[k - 2].azimuth
                              : blocks.size() >= 2 ? blocks[blocks.size() - 2].azimuth
                                                   : last;
      const int step = (int(last) - int(before) + kHdl32eAzimuthUnits) % kHdl32eAzimuthUnits;
      packet.blocks[k].azimuth = uint16_t((last + step) % kHdl32eAzimuthUnits);
    }
    const int64_t stamp = rotation.start_ns + int64_t(first) * rotation.cycle_period_ns;
    packet.usec_past_hour = usec_past_hour(stamp);
    packets.push_back({stamp, encode_hdl32e_packet(packet)});
  }
  return packets;
}

std::vector<Hdl32eBlock> hdl32e_blocks(const ros2::VelodyneScan& scan, const std::string& context) {
  std::vector<Hdl32eBlock> blocks;
  blocks.reserve(scan.packets.size() * kHdl32eBlocksPerPacket);
  for (size_t i = 0; i < scan.packets.size(); ++i) {
    const Hdl32eDataPacket p = decode_hdl32e_packet(scan.packets[i].data, context + ": packet " + std::to_string(i));
    blocks.insert(blocks.end(), p.blocks.begin(), p.blocks.end());
  }
  return blocks;
}

uint8_t nmea_checksum(std::string_view sentence) {
  const size_t begin = sentence.find('$'), end = sentence.find('*');
  uint8_t sum = 0;
  for (size_t i = begin == std::string_view::npos ? 0 : begin + 1; i < std::min(end, sentence.size()); ++i)
    sum ^= uint8_t(sentence[i]);
  return sum;
}

std::string gprmc_sentence(int64_t t_ns, const GpsFix& fix, double speed_mps) {
  const std::time_t sec = std::time_t(floor_div(t_ns, 1'000'000'000));
  std::tm tm{};
  gmtime_r(&sec, &tm);
  char clock[40], date[40];  // room for any int, though the fields are two digits
  std::snprintf(clock, sizeof clock, "%02d%02d%02d", tm.tm_hour, tm.tm_min, tm.tm_sec);
  std::snprintf(date, sizeof date, "%02d%02d%02d", tm.tm_mday, tm.tm_mon + 1, tm.tm_year % 100);
  std::string body = std::string("GPRMC,") + clock;
  if (fix.status == GpsStatus::no_fix) {
    body += ",V,,,,,,," + std::string(date) + ",,,N";
  } else {
    // Course over ground: true north, clockwise; the fix's heading is from east, counter-clockwise.
    double course = std::fmod(90.0 - fix.heading_rad * 180.0 / M_PI, 360.0);
    if (course < 0) course += 360.0;
    char motion[48];
    std::snprintf(motion, sizeof motion, "%.1f,%.1f", std::abs(speed_mps) * kKnotsPerMps, course);
    // Mode indicator (NMEA 2.3): D differential (RTK-grade fixes), A autonomous.
    body += ",A," + nmea_angle(fix.lat_deg, 2, 'N', 'S') + "," + nmea_angle(fix.lon_deg, 3, 'E', 'W') + "," + motion +
            "," + date + ",,," + (fix.status == GpsStatus::rtk ? "D" : "A");
  }
  char tail[16];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", nmea_checksum("$" + body + "*"));
  return "$" + body + tail;
}

std::array<uint8_t, kHdl32ePositionPacketSize> encode_hdl32e_position_packet(int64_t t_ns, std::string_view nmea) {
  std::array<uint8_t, kHdl32ePositionPacketSize> out{};
  put32(out.data() + kPositionTimestampOffset, usec_past_hour(t_ns));
  // The sentence must leave a NUL before the end (readers take it as a C string).
  if (nmea.size() >= out.size() - kNmeaOffset) throw InputError("NMEA sentence too long for a position packet");
  std::copy(nmea.begin(), nmea.end(), out.begin() + kNmeaOffset);
  return out;
}

}  // namespace lidarloop
