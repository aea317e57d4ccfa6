#include "logs/pcap_file.hpp"

#include <cerrno>
#include <cstring>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {

constexpr uint32_t kPcapMagic = 0xa1b2c3d4;  // microsecond timestamps, written little endian
constexpr uint16_t kPcapMajor = 2, kPcapMinor = 4;
constexpr uint32_t kSnapLength = 65535;
constexpr uint32_t kLinkTypeEthernet = 1;
constexpr uint16_t kEtherTypeIpv4 = 0x0800;
constexpr size_t kEthernetHeader = 14, kIpv4Header = 20, kUdpHeader = 8;
constexpr uint8_t kIpv4VersionIhl = 0x45;  // version 4, 5 words: no options
constexpr uint16_t kDontFragment = 0x4000;
constexpr uint8_t kTtl = 255, kProtocolUdp = 17;

void le16(std::vector<uint8_t>& out, uint16_t v) { out.insert(out.end(), {uint8_t(v), uint8_t(v >> 8)}); }
void le32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}
void be16(std::vector<uint8_t>& out, uint16_t v) { out.insert(out.end(), {uint8_t(v >> 8), uint8_t(v)}); }

}  // namespace

std::array<uint8_t, 24> pcap_file_header() {
  std::vector<uint8_t> h;
  le32(h, kPcapMagic);
  le16(h, kPcapMajor);
  le16(h, kPcapMinor);
  le32(h, 0);  // thiszone: UTC
  le32(h, 0);  // sigfigs
  le32(h, kSnapLength);
  le32(h, kLinkTypeEthernet);
  std::array<uint8_t, 24> out{};
  std::copy(h.begin(), h.end(), out.begin());
  return out;
}

uint16_t ipv4_header_checksum(std::span<const uint8_t> header) {
  uint32_t sum = 0;
  for (size_t i = 0; i + 1 < header.size(); i += 2) sum += uint32_t(header[i]) << 8 | header[i + 1];
  if (header.size() % 2) sum += uint32_t(header.back()) << 8;
  while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
  return uint16_t(~sum);
}

std::vector<uint8_t> udp_frame(const UdpEndpoints& e, uint16_t port, uint16_t ip_id, std::span<const uint8_t> payload) {
  std::vector<uint8_t> f;
  f.reserve(kEthernetHeader + kIpv4Header + kUdpHeader + payload.size());
  f.insert(f.end(), 6, 0xff);  // broadcast
  f.insert(f.end(), e.source_mac.begin(), e.source_mac.end());
  be16(f, kEtherTypeIpv4);
  const size_t ip = f.size();
  f.push_back(kIpv4VersionIhl);
  f.push_back(0);  // DSCP, ECN
  be16(f, uint16_t(kIpv4Header + kUdpHeader + payload.size()));
  be16(f, ip_id);
  be16(f, kDontFragment);
  f.push_back(kTtl);
  f.push_back(kProtocolUdp);
  be16(f, 0);  // checksum, below
  f.insert(f.end(), e.source_ip.begin(), e.source_ip.end());
  f.insert(f.end(), e.destination_ip.begin(), e.destination_ip.end());
  const uint16_t checksum = ipv4_header_checksum(std::span(f).subspan(ip, kIpv4Header));
  f[ip + 10] = uint8_t(checksum >> 8), f[ip + 11] = uint8_t(checksum);
  be16(f, port);
  be16(f, port);
  be16(f, uint16_t(kUdpHeader + payload.size()));
  be16(f, 0);  // no UDP checksum
  f.insert(f.end(), payload.begin(), payload.end());
  return f;
}

PcapWriter::PcapWriter(const std::string& path, const UdpEndpoints& endpoints)
    : path_(path), endpoints_(endpoints), out_(path, std::ios::binary) {
  if (!out_) throw InputError(path + ": cannot write file (" + std::strerror(errno) + ")");
  const auto header = pcap_file_header();
  out_.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
}

void PcapWriter::write_udp(int64_t t_ns, uint16_t port, std::span<const uint8_t> payload) {
  const std::vector<uint8_t> frame = udp_frame(endpoints_, port, uint16_t(count_), payload);
  const int64_t us = std::max<int64_t>(t_ns, 0) / 1000;
  std::vector<uint8_t> record;
  le32(record, uint32_t(us / 1'000'000));
  le32(record, uint32_t(us % 1'000'000));
  le32(record, uint32_t(frame.size()));  // captured length
  le32(record, uint32_t(frame.size()));  // length on the wire
  out_.write(reinterpret_cast<const char*>(record.data()), std::streamsize(record.size()));
  out_.write(reinterpret_cast<const char*>(frame.data()), std::streamsize(frame.size()));
  ++count_;
}

void PcapWriter::close() {
  if (!out_.flush()) throw InputError(path_ + ": write failed");
  out_.close();
}

}  // namespace lidarloop
