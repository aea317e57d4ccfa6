#pragma once
// Classic pcap capture files (libpcap format: microsecond timestamps, link type Ethernet) of the UDP
// datagrams a LiDAR broadcasts, for tools that replay a sensor from a capture (VeloView, the ROS
// velodyne driver's `pcap` parameter, Wireshark).
//
// Each datagram is framed as the sensor sends it: Ethernet II (broadcast destination, the sender's
// MAC), IPv4 without options (header checksum filled in, don't-fragment, TTL 255), UDP from and to
// the same port (checksum 0: optional over IPv4, RFC 768). The ROS driver reads the payload at byte
// 42 = 14 + 20 + 8 of the frame (velodyne_driver input.cpp), so there must be no IP options or VLAN tag.
#include <array>
#include <cstdint>
#include <fstream>
#include <span>
#include <string>
#include <vector>

namespace lidarloop {

struct UdpEndpoints {
  std::array<uint8_t, 6> source_mac{};
  std::array<uint8_t, 4> source_ip{}, destination_ip{};
};

// The 24-byte global header: magic a1b2c3d4 (microseconds), version 2.4, snaplen 65535, LINKTYPE_ETHERNET.
std::array<uint8_t, 24> pcap_file_header();
// The Internet checksum (RFC 1071) of an IPv4 header whose checksum field is zero.
uint16_t ipv4_header_checksum(std::span<const uint8_t> header);
// One Ethernet frame carrying `payload` in UDP from and to `port`; `ip_id` is the IPv4 identification.
std::vector<uint8_t> udp_frame(const UdpEndpoints& endpoints, uint16_t port, uint16_t ip_id,
                               std::span<const uint8_t> payload);

class PcapWriter {
 public:
  // InputError if the file cannot be written.
  PcapWriter(const std::string& path, const UdpEndpoints& endpoints);
  // A datagram captured at t_ns (ns since the Unix epoch, >= 0).
  void write_udp(int64_t t_ns, uint16_t port, std::span<const uint8_t> payload);
  void close();  // flushes; InputError on a failed write
  size_t count() const { return count_; }

 private:
  std::string path_;
  UdpEndpoints endpoints_;
  std::ofstream out_;
  size_t count_ = 0;
};

}  // namespace lidarloop
