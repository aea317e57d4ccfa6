#pragma once
// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320; zlib, PNG, gzip): the checksum of intensity
// map tiles and the one MCAP uses for chunks, attachments, the data section and the summary.
// Slicing-by-8: every byte of a log passes through it twice (chunk records, then the data section),
// and a tile (1.2 MB) is checked when the car drives into it, inside a scan's time budget.
#include <cstddef>
#include <cstdint>

namespace lidarloop {

class Crc32 {
 public:
  Crc32() = default;
  // Continues a CRC from the value of the bytes before: CRC-32's state is the complement of its value.
  static Crc32 resume(uint32_t value) {
    Crc32 c;
    c.state_ = ~value;
    return c;
  }
  void update(const void* data, size_t size);
  uint32_t value() const { return ~state_; }

 private:
  uint32_t state_ = 0xFFFFFFFFu;
};

inline uint32_t crc32(const void* data, size_t size) {
  Crc32 crc;
  crc.update(data, size);
  return crc.value();
}

}  // namespace lidarloop
