// The HDL-32E's wire format as the tests and `export --pcap` read it back: a 1206-byte data packet
// (decode_hdl32e_packet), and a velodyne_msgs/msg/VelodyneScan message with its packets. A packet the
// decoder accepts has no byte it ignores, so encoding what it decoded must give the input back.
#include <cstdlib>
#include <iostream>

#include "common/input_error.hpp"
#include "logs/hdl32e_packets.hpp"
#include "logs/ros2_messages.hpp"

namespace {
using namespace lidarloop;

void decode_packet(std::span<const uint8_t> bytes) {
  Hdl32eDataPacket packet;
  try {
    packet = decode_hdl32e_packet(bytes, "fuzz packet");
  } catch (const InputError&) {
    return;
  }
  const auto again = encode_hdl32e_packet(packet);
  if (!std::equal(again.begin(), again.end(), bytes.begin(), bytes.end())) {
    std::cerr << "a data packet decoded and encoded again differs from the input\n";
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  decode_packet(bytes);
  try {
    for (const auto& p : ros2::decode_velodyne_scan(bytes, "fuzz VelodyneScan").packets) decode_packet(p.data);
  } catch (const InputError&) {
  }
  return 0;
}
