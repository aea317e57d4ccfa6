#pragma once
// The Velodyne HDL-32E's UDP packets, byte for byte, so a stack that starts from the sensor's wire
// (the ROS velodyne driver, TIER IV's nebula, VeloView) can take lidarloop's scans.
//
// Data packet (port 2368), 1206 bytes of UDP payload:
//   12 blocks of 100 bytes, block b at 100 b:
//     +0  0xFF 0xEE      block flag (upper bank; uint16 0xEEFF little endian: UPPER_BANK in the ROS
//                        driver's rawdata.hpp, BlockId.Block_0_To_31 in @foxglove/velodyne-cloud)
//     +2  azimuth        uint16 LE, 0.01 deg, [0, 35999]
//     +4  32 x {distance uint16 LE in 2 mm units (0 = no return), intensity uint8}, in channel order
//   1200  timestamp      uint32 LE, microseconds past the top of the hour
//   1204  return mode    0x37 strongest (0x38 last, 0x39 dual: @foxglove/velodyne-cloud ReturnMode)
//   1205  product id     0x21 HDL-32E (@foxglove/velodyne-cloud FactoryId; the ROS driver reads byte
//                        1205 as the model id too)
// One block is one firing cycle of the 32 lasers (46.08 us); channel j of a block is laser_id j of
// the HDL-32E calibration (elevations -30.67, -9.33, -29.33, ...: 32db.yaml / 32db.json), the order
// the lasers fire in. The timestamp is that of the packet's first block (its first firing).
//
// Position packet (port 8308), 512 bytes: zeros except
//   198  timestamp       uint32 LE, microseconds past the top of the hour
//   206  NMEA sentence   $GPRMC...*hh\r\n, NUL padded
// (offsets as VeloView's vtkVelodyneHDLPositionReader and MRPT's TVelodynePositionPacket read them:
// 14 zero bytes, the gyro/temperature/accelerometer words, 160 unused bytes, the timestamp, 4 unused
// bytes, the sentence). The sensor relays its GPS receiver's once-a-second $GPRMC, stamped at the
// second's pulse; lidarloop's IMU words are zero (no IMU is simulated).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/hdl32e_block.hpp"
#include "common/vehicle_messages.hpp"
#include "logs/ros2_messages.hpp"

namespace lidarloop {

inline constexpr size_t kHdl32eDataPacketSize = 1206;
inline constexpr size_t kHdl32ePositionPacketSize = 512;
inline constexpr int kHdl32eBlocksPerPacket = 12;
inline constexpr uint16_t kHdl32eDataPort = 2368;      // HDL-32E manual; DATA_PORT_NUMBER in the ROS driver
inline constexpr uint16_t kHdl32ePositionPort = 8308;  // HDL-32E manual; POSITION_PORT_NUMBER in the ROS driver
inline constexpr uint8_t kStrongestReturn = 0x37, kLastReturn = 0x38, kDualReturn = 0x39;
inline constexpr uint8_t kHdl32eProductId = 0x21;

struct Hdl32eDataPacket {
  std::array<Hdl32eBlock, kHdl32eBlocksPerPacket> blocks{};
  uint32_t usec_past_hour = 0;
  uint8_t return_mode = kStrongestReturn;
};

std::array<uint8_t, kHdl32eDataPacketSize> encode_hdl32e_packet(const Hdl32eDataPacket& packet);
// The inverse. InputError "<context>: ..." unless the bytes are an HDL-32E single-return data packet:
// 1206 bytes, every block flagged 0xFF 0xEE with an azimuth below 36000, a timestamp within the
// hour, return mode strongest or last, product id HDL-32E. A pure function of the bytes.
Hdl32eDataPacket decode_hdl32e_packet(std::span<const uint8_t> bytes,
                                      const std::string& context = "HDL-32E data packet");

// Microseconds past the top of the hour of a time in ns since the Unix epoch (the log's clock).
uint32_t usec_past_hour(int64_t t_ns);

// A revolution's blocks in packets of 12, each stamped with its first block's time on the sensor's
// clock (its timestamp bytes, which a driver with `gps_time` reads). The last packet is filled with
// empty blocks (no returns, the azimuth stepping on), so a scan's packets hold exactly its returns:
// 2170 cycles at 10 Hz give 181 packets, as the ROS driver's ceil(1808 / 10) per scan.
std::vector<ros2::VelodynePacket> hdl32e_data_packets(const Hdl32eRotation& rotation);
// What a driver reads back: the blocks of a scan's packets in order, the last packet's padding
// included (it holds no returns). InputError "<context>: packet N: ..." for a packet that is not an
// HDL-32E data packet.
std::vector<Hdl32eBlock> hdl32e_blocks(const ros2::VelodyneScan& scan, const std::string& context);

// "$GPRMC,hhmmss,A,ddmm.mmmmm,N,dddmm.mmmmm,E,knots,course,ddmmyy,,,A*hh\r\n" at UTC time t_ns (ns since
// the Unix epoch); status V with empty position fields when `fix` has no fix. `speed_mps` gives the
// speed over ground; the course is the fix's heading.
std::string gprmc_sentence(int64_t t_ns, const GpsFix& fix, double speed_mps);
// XOR of the characters between '$' and '*' (NMEA 0183).
uint8_t nmea_checksum(std::string_view sentence);

std::array<uint8_t, kHdl32ePositionPacketSize> encode_hdl32e_position_packet(int64_t t_ns, std::string_view nmea);

}  // namespace lidarloop
