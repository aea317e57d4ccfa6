#pragma once
// CDR, as ROS 2 puts messages on the wire and in bags (OMG XCDR version 1, little endian): a 4-byte
// encapsulation header 00 01 00 00, then the fields in order, each primitive aligned to its own size
// (8-byte values to 8) counted from the end of the header; strings as a uint32 length that includes
// a terminating NUL; sequences as a uint32 element count; fixed-size arrays as bare elements.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lidarloop {

class CdrWriter {
 public:
  CdrWriter();
  // Writes into `reuse` (emptied first), so a caller encoding big messages keeps one allocation.
  explicit CdrWriter(std::vector<uint8_t>&& reuse);

  void u8(uint8_t v) { put(v, 1); }
  void i8(int8_t v) { put(uint8_t(v), 1); }
  void boolean(bool v) { put(v ? 1 : 0, 1); }
  void u16(uint16_t v) { put(v, 2); }
  void u32(uint32_t v) { put(v, 4); }
  void i32(int32_t v) { put(uint32_t(v), 4); }
  void u64(uint64_t v) { put(v, 8); }
  void f32(float v);
  void f64(double v);
  void string(std::string_view s);
  void sequence_length(size_t n);            // a sequence's element count
  void raw(std::span<const uint8_t> bytes);  // uint8 elements: no alignment, no count

  size_t size() const { return buf_.size(); }
  std::vector<uint8_t>& buffer() { return buf_; }
  // Reserves room for a known payload, so a point cloud is copied once.
  void reserve(size_t n) { buf_.reserve(buf_.size() + n); }

 private:
  void align(size_t n);
  void put(uint64_t v, size_t n);
  std::vector<uint8_t> buf_;
};

// Every read is bounds-checked; InputError "<context>: ..." when the message is shorter than its
// schema says, has an unsupported encapsulation, or claims a sequence longer than what is left.
class CdrReader {
 public:
  CdrReader(std::span<const uint8_t> data, std::string context);

  uint8_t u8() { return uint8_t(get(1)); }
  int8_t i8() { return int8_t(get(1)); }
  bool boolean() { return get(1) != 0; }
  uint16_t u16() { return uint16_t(get(2)); }
  uint32_t u32() { return uint32_t(get(4)); }
  int32_t i32() { return int32_t(uint32_t(get(4))); }
  uint64_t u64() { return get(8); }
  float f32();
  double f64();
  std::string string();
  // A sequence's element count, checked against the bytes left for elements of `element_size`.
  uint32_t sequence_length(size_t element_size);
  std::span<const uint8_t> raw(size_t n);

  size_t remaining() const { return data_.size() - pos_; }
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  void align(size_t n);
  uint64_t get(size_t n);
  std::span<const uint8_t> data_;
  size_t pos_ = 4;
  std::string context_;
};

}  // namespace lidarloop
