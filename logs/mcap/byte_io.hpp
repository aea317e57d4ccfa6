#pragma once
// Little-endian byte packing for MCAP records: ByteWriter appends to a buffer, ByteReader walks one
// with every read bounds-checked. MCAP's own framing (uint32-prefixed strings, maps and arrays) lives
// here; CDR, which aligns, has its own writer and reader (cdr.hpp).
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/little_endian.hpp"

namespace lidarloop {

class ByteWriter {
 public:
  void u8(uint8_t v) { buf_.push_back(v); }
  void u16(uint16_t v) { le(v, 2); }
  void u32(uint32_t v) { le(v, 4); }
  void u64(uint64_t v) { le(v, 8); }
  void bytes(std::span<const uint8_t> b) { buf_.insert(buf_.end(), b.begin(), b.end()); }
  void bytes(std::string_view b) { buf_.insert(buf_.end(), b.begin(), b.end()); }
  void string(std::string_view s);                               // uint32 length + bytes
  void string_map(const std::map<std::string, std::string>& m);  // uint32 byte length + key/value strings

  // Overwrites 4 or 8 bytes at `pos`, for length prefixes known only after their content.
  void patch_u32(size_t pos, uint32_t v) { patch(pos, v, 4); }
  void patch_u64(size_t pos, uint64_t v) { patch(pos, v, 8); }

  size_t size() const { return buf_.size(); }
  std::vector<uint8_t>& buffer() { return buf_; }
  const std::vector<uint8_t>& buffer() const { return buf_; }

 private:
  void le(uint64_t v, int n) { append_le(buf_, v, n); }
  void patch(size_t pos, uint64_t v, int n);
  std::vector<uint8_t> buf_;
};

// Reads from a span it does not own. Running past the end, or a length prefix longer than what is
// left, throws InputError "<context>: <what> truncated"; `context` names the file and the record.
class ByteReader {
 public:
  ByteReader(std::span<const uint8_t> data, std::string context) : data_(data), context_(std::move(context)) {}

  uint8_t u8(const char* what);
  uint16_t u16(const char* what);
  uint32_t u32(const char* what);
  uint64_t u64(const char* what);
  std::string string(const char* what);
  std::span<const uint8_t> bytes(size_t n, const char* what);
  std::map<std::string, std::string> string_map(const char* what);

  size_t offset() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }
  std::span<const uint8_t> rest() const { return data_.subspan(pos_); }
  const std::string& context() const { return context_; }
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  uint64_t le(int n, const char* what);
  std::span<const uint8_t> data_;
  size_t pos_ = 0;
  std::string context_;
};

}  // namespace lidarloop
