// The HDL-32E's UDP packets (logs/hdl32e_packets.hpp), the pcap framing around them
// (logs/pcap_file.hpp) and velodyne_msgs/msg/VelodyneScan, checked byte for byte against the layout
// the decoders read (ROS velodyne driver, @foxglove/velodyne-cloud, VeloView) and hand-computed values.
#include <cmath>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "logs/hdl32e_packets.hpp"
#include "logs/pcap_file.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/ros2_schemas.hpp"

namespace lidarloop {
namespace {

Hdl32eDataPacket known_packet() {
  Hdl32eDataPacket p;
  for (int b = 0; b < kHdl32eBlocksPerPacket; ++b) {
    p.blocks[b].azimuth = uint16_t(12345 + 16 * b);  // 123.45 deg, stepping 0.16 deg
    for (int j = 0; j < kHdl32eChannels; ++j) {
      p.blocks[b].distance[j] = uint16_t(1000 * b + 31 * j);
      p.blocks[b].intensity[j] = uint8_t(7 * j + b);
    }
  }
  p.blocks[0].distance[0] = 5000;  // 10 m
  p.blocks[0].intensity[0] = 77;
  p.blocks[0].distance[31] = 0x1234;
  p.usec_past_hour = 0x01020304;
  return p;
}

TEST(Hdl32ePackets, AKnownFiringHasTheExactBytes) {
  const auto bytes = encode_hdl32e_packet(known_packet());
  ASSERT_EQ(bytes.size(), 1206u);
  // Block 0: flag FF EE, azimuth 12345 = 0x3039 little endian, channel 0 = 5000 = 0x1388 then 77.
  EXPECT_EQ(bytes[0], 0xFF);
  EXPECT_EQ(bytes[1], 0xEE);
  EXPECT_EQ(bytes[2], 0x39);
  EXPECT_EQ(bytes[3], 0x30);
  EXPECT_EQ(bytes[4], 0x88);
  EXPECT_EQ(bytes[5], 0x13);
  EXPECT_EQ(bytes[6], 77);
  // Channel 31 of block 0 at 4 + 3 * 31 = 97.
  EXPECT_EQ(bytes[97], 0x34);
  EXPECT_EQ(bytes[98], 0x12);
  // Block 1 at 100: its flag and azimuth 12361 = 0x3049.
  EXPECT_EQ(bytes[100], 0xFF);
  EXPECT_EQ(bytes[101], 0xEE);
  EXPECT_EQ(bytes[102], 0x49);
  EXPECT_EQ(bytes[103], 0x30);
  // Block 11, channel 2: distance 11062 = 0x2B36, intensity 25, at 1100 + 4 + 6.
  EXPECT_EQ(bytes[1110], 0x36);
  EXPECT_EQ(bytes[1111], 0x2B);
  EXPECT_EQ(bytes[1112], 25);
  // Timestamp, then the factory bytes: strongest return, HDL-32E.
  EXPECT_EQ(bytes[1200], 0x04);
  EXPECT_EQ(bytes[1201], 0x03);
  EXPECT_EQ(bytes[1202], 0x02);
  EXPECT_EQ(bytes[1203], 0x01);
  EXPECT_EQ(bytes[1204], 0x37);
  EXPECT_EQ(bytes[1205], 0x21);
}

TEST(Hdl32ePackets, DecodeInvertsEncode) {
  const Hdl32eDataPacket p = known_packet();
  const Hdl32eDataPacket q = decode_hdl32e_packet(encode_hdl32e_packet(p));
  EXPECT_EQ(q.usec_past_hour, p.usec_past_hour);
  EXPECT_EQ(q.return_mode, kStrongestReturn);
  for (int b = 0; b < kHdl32eBlocksPerPacket; ++b) {
    EXPECT_EQ(q.blocks[b].azimuth, p.blocks[b].azimuth);
    EXPECT_EQ(q.blocks[b].distance, p.blocks[b].distance);
    EXPECT_EQ(q.blocks[b].intensity, p.blocks[b].intensity);
  }
}

void expect_rejected(std::span<const uint8_t> bytes, const std::string& message) {
  try {
    decode_hdl32e_packet(bytes, "scan.mcap: packet 3");
    ADD_FAILURE() << "accepted, expected: " << message;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scan.mcap: packet 3: " + message), std::string::npos) << e.what();
  }
}

TEST(Hdl32ePackets, DecoderRejectsGarbage) {
  const auto good = encode_hdl32e_packet(known_packet());
  expect_rejected(std::span(good).first(1205), "1205 bytes, a data packet has 1206");
  expect_rejected({}, "0 bytes");
  auto bad = good;
  bad[500] = 0xDD;  // block 5's flag: lower bank, which an HDL-32E never sends
  expect_rejected(bad, "block 5 has no 0xFF 0xEE flag");
  bad = good;
  bad[702] = 0xA0, bad[703] = 0x8C;  // block 7 azimuth 36000
  expect_rejected(bad, "block 7 azimuth 36000 is not below 36000");
  bad = good;
  bad[1205] = 0x22;  // a VLP-16
  expect_rejected(bad, "product id 34 is not the HDL-32E's");
  bad = good;
  bad[1204] = 0x39;
  expect_rejected(bad, "return mode 57 is not single return");
  bad = good;
  bad[1203] = 0xFF;  // 0xFF020304 = 4278321924 us: more than an hour
  expect_rejected(bad, "timestamp 4278321924 us is past the hour");
}

TEST(Hdl32ePackets, TimestampIsMicrosecondsPastTheHour) {
  EXPECT_EQ(usec_past_hour(0), 0u);
  EXPECT_EQ(usec_past_hour(5 * 3600'000'000'000LL + 1'500'000'999), 1'500'000u);
  EXPECT_EQ(usec_past_hour(3600'000'000'000LL - 1000), 3'599'999'999u);
}

TEST(Hdl32ePackets, ARevolutionFillsPacketsOfTwelveBlocks) {
  Hdl32eRotation r{7'200'000'000'000 + 250'000'000, 46080, std::vector<Hdl32eBlock>(2170)};
  for (size_t k = 0; k < r.blocks.size(); ++k) {
    r.blocks[k].azimuth = uint16_t((18000 + 17 * k) % 36000);
    r.blocks[k].distance[k % 32] = uint16_t(1 + k);
  }
  const auto packets = hdl32e_data_packets(r);
  ASSERT_EQ(packets.size(), 181u);  // ceil(2170 / 12), the ROS driver's ceil(1808 / 10)
  for (size_t i = 0; i < packets.size(); ++i) {
    const int64_t stamp = r.start_ns + int64_t(i) * 12 * 46080;
    EXPECT_EQ(packets[i].stamp_ns, stamp);
    const Hdl32eDataPacket p = decode_hdl32e_packet(packets[i].data);
    EXPECT_EQ(p.usec_past_hour, usec_past_hour(stamp));
    for (size_t b = 0; b < 12 && 12 * i + b < r.blocks.size(); ++b) {
      EXPECT_EQ(p.blocks[b].azimuth, r.blocks[12 * i + b].azimuth);
      EXPECT_EQ(p.blocks[b].distance, r.blocks[12 * i + b].distance);
    }
  }
  // 2170 = 180 * 12 + 10: the last packet ends with two empty blocks, the azimuth stepping on by 17.
  const Hdl32eDataPacket last = decode_hdl32e_packet(packets.back().data);
  EXPECT_EQ(last.blocks[10].azimuth, (18000 + 17 * 2170) % 36000);
  EXPECT_EQ(last.blocks[11].azimuth, (18000 + 17 * 2171) % 36000);
  for (int b : {10, 11})
    for (int j = 0; j < 32; ++j) EXPECT_EQ(last.blocks[b].distance[j], 0);
}

TEST(Hdl32ePackets, ADriverReadsBackARevolutionsBlocks) {
  Hdl32eRotation r{250'000'000, 46080, std::vector<Hdl32eBlock>(30)};
  for (size_t k = 0; k < r.blocks.size(); ++k) {
    r.blocks[k].azimuth = uint16_t(100 * k);
    r.blocks[k].distance[k % 32] = uint16_t(500 + k);
    r.blocks[k].intensity[k % 32] = uint8_t(k);
  }
  const ros2::VelodyneScan scan{r.start_ns, "lidar", hdl32e_data_packets(r)};
  const std::vector<Hdl32eBlock> blocks = hdl32e_blocks(scan, "scan");
  ASSERT_EQ(blocks.size(), 36u);  // 3 packets: 30 blocks and 6 empty ones after them
  for (size_t k = 0; k < blocks.size(); ++k) {
    if (k >= r.blocks.size()) {
      EXPECT_EQ(blocks[k].distance, Hdl32eBlock{}.distance);
      continue;
    }
    EXPECT_EQ(blocks[k].azimuth, r.blocks[k].azimuth);
    EXPECT_EQ(blocks[k].distance, r.blocks[k].distance);
    EXPECT_EQ(blocks[k].intensity, r.blocks[k].intensity);
  }
  ros2::VelodyneScan broken = scan;
  broken.packets[2].data[1205] = 0x22;  // not an HDL-32E
  try {
    hdl32e_blocks(broken, "log.mcap /velodyne_packets");
    FAIL() << "a packet of another product was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("log.mcap /velodyne_packets: packet 2"), std::string::npos) << e.what();
  }
}

TEST(Hdl32ePackets, NmeaChecksumMatchesAHandComputedSentence) {
  // The textbook RMC example; its checksum 6A is the XOR of every character between $ and *.
  EXPECT_EQ(nmea_checksum("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"), 0x6A);
  GpsFix fix;
  fix.status = GpsStatus::fix;
  fix.lat_deg = 48.1173;                                           // 48 deg 07.038'
  fix.lon_deg = 11.0 + 31.0 / 60.0;                                // 11 deg 31.000'
  fix.heading_rad = (90.0 - 84.4) * M_PI / 180;                    // course 84.4 deg from north
  const int64_t t = ((12 * 60 + 35) * 60 + 19) * 1'000'000'000LL;  // 1970-01-01 12:35:19 UTC
  EXPECT_EQ(gprmc_sentence(t, fix, 22.4 * 1852.0 / 3600.0),
            "$GPRMC,123519,A,4807.03800,N,01131.00000,E,22.4,84.4,010170,,,A*74\r\n");
  fix.status = GpsStatus::no_fix;
  const std::string void_fix = gprmc_sentence(t, fix, 0);
  EXPECT_EQ(void_fix.substr(0, void_fix.find('*')), "$GPRMC,123519,V,,,,,,,010170,,,N");
  char sum[3];
  std::snprintf(sum, sizeof sum, "%02X", nmea_checksum(void_fix));
  EXPECT_EQ(void_fix.substr(void_fix.find('*') + 1, 2), sum);
}

TEST(Hdl32ePackets, PositionPacketCarriesTimestampAndSentence) {
  const std::string nmea = "$GPRMC,000001,V,,,,,,,010170,,,N*4A\r\n";
  const auto p = encode_hdl32e_position_packet(3601'000'000'000LL, nmea);
  ASSERT_EQ(p.size(), 512u);
  for (size_t i = 0; i < 198; ++i) ASSERT_EQ(p[i], 0) << i;
  // 1 s past the hour = 1000000 us = 0x000F4240.
  EXPECT_EQ(p[198], 0x40);
  EXPECT_EQ(p[199], 0x42);
  EXPECT_EQ(p[200], 0x0F);
  EXPECT_EQ(p[201], 0x00);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(&p[206]), nmea.size()), nmea);
  EXPECT_EQ(p[206 + nmea.size()], 0);
}

TEST(PcapFile, GlobalHeaderBytes) {
  const std::array<uint8_t, 24> expected = {0xd4, 0xc3, 0xb2, 0xa1, 2,    0,    4, 0, 0, 0, 0, 0,
                                            0,    0,    0,    0,    0xff, 0xff, 0, 0, 1, 0, 0, 0};
  EXPECT_EQ(pcap_file_header(), expected);
}

TEST(PcapFile, Ipv4ChecksumOfAKnownHeader) {
  // 192.168.0.1 -> 192.168.0.199, UDP, TTL 64, DF: the worked example of RFC 1071's sum, 0xB861.
  const std::array<uint8_t, 20> header = {0x45, 0x00, 0x00, 0x73, 0x00, 0x00, 0x40, 0x00, 0x40, 0x11,
                                          0x00, 0x00, 0xc0, 0xa8, 0x00, 0x01, 0xc0, 0xa8, 0x00, 0xc7};
  EXPECT_EQ(ipv4_header_checksum(header), 0xB861);
}

TEST(PcapFile, UdpFrameLayout) {
  const UdpEndpoints e{{0x60, 0x76, 0x88, 0, 0, 1}, {192, 168, 1, 201}, {255, 255, 255, 255}};
  const std::vector<uint8_t> payload(1206, 0xAB);
  const std::vector<uint8_t> f = udp_frame(e, 2368, 7, payload);
  ASSERT_EQ(f.size(), 42u + 1206u);  // the ROS driver reads the payload at byte 42
  for (int i = 0; i < 6; ++i) EXPECT_EQ(f[i], 0xff);
  EXPECT_EQ(f[6], 0x60);
  EXPECT_EQ(f[12], 0x08);  // EtherType IPv4
  EXPECT_EQ(f[13], 0x00);
  EXPECT_EQ(f[14], 0x45);
  EXPECT_EQ(f[16] << 8 | f[17], 20 + 8 + 1206);  // total length
  EXPECT_EQ(f[18] << 8 | f[19], 7);              // identification
  EXPECT_EQ(f[23], 17);                          // UDP
  EXPECT_EQ(f[26], 192);
  EXPECT_EQ(f[29], 201);
  EXPECT_EQ(f[30], 255);
  // A header with its checksum filled in sums to zero.
  EXPECT_EQ(ipv4_header_checksum(std::span(f).subspan(14, 20)), 0);
  EXPECT_EQ(f[34] << 8 | f[35], 2368);
  EXPECT_EQ(f[36] << 8 | f[37], 2368);
  EXPECT_EQ(f[38] << 8 | f[39], 8 + 1206);
  EXPECT_EQ(f[42], 0xAB);
}

TEST(VelodyneScan, CdrRoundTripAndSchema) {
  ros2::VelodyneScan scan{1'500'000'123, "lidar", {}};
  for (int i = 0; i < 3; ++i) {
    ros2::VelodynePacket p;
    p.stamp_ns = scan.stamp_ns + i * 552960;
    p.data = encode_hdl32e_packet(known_packet());
    p.data[7] = uint8_t(i);
    scan.packets.push_back(p);
  }
  const ros2::Bytes cdr = ros2::encode_velodyne_scan(scan);
  // 4 encapsulation + 8 stamp + 4 + 6 ("lidar\0") + 2 padding + 4 count + 3 x (8 + 1206) + 2 x 2 padding.
  EXPECT_EQ(cdr.size(), 4u + 8 + 4 + 6 + 2 + 4 + 3 * (8 + 1206) + 2 * 2);
  const ros2::VelodyneScan back = ros2::decode_velodyne_scan(cdr, "test");
  EXPECT_EQ(back.stamp_ns, scan.stamp_ns);
  EXPECT_EQ(back.frame_id, "lidar");
  ASSERT_EQ(back.packets.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(back.packets[i].stamp_ns, scan.packets[i].stamp_ns);
    EXPECT_EQ(back.packets[i].data, scan.packets[i].data);
  }
  EXPECT_THROW(ros2::decode_velodyne_scan(std::span(cdr).first(cdr.size() - 1), "test"), InputError);
  const std::string schema = ros2::schema_text("velodyne_msgs/msg/VelodyneScan");
  EXPECT_EQ(schema.rfind("std_msgs/Header header\nvelodyne_msgs/VelodynePacket[] packets\n", 0), 0u);
  EXPECT_NE(schema.find("MSG: velodyne_msgs/VelodynePacket\nbuiltin_interfaces/Time stamp\nuint8[1206] data\n"),
            std::string::npos);
}

}  // namespace
}  // namespace lidarloop
