#include "logs/mcap/byte_io.hpp"

#include <stdexcept>

#include "common/input_error.hpp"

namespace lidarloop {

void ByteWriter::string(std::string_view s) {
  u32(uint32_t(s.size()));
  bytes(s);
}

void ByteWriter::string_map(const std::map<std::string, std::string>& m) {
  const size_t start = size();
  u32(0);
  for (const auto& [key, value] : m) {
    string(key);
    string(value);
  }
  patch_u32(start, uint32_t(size() - start - 4));
}

void ByteWriter::patch(size_t pos, uint64_t v, int n) {
  if (pos + size_t(n) > buf_.size()) throw std::out_of_range("ByteWriter::patch: past the end of the buffer");
  put_le(buf_.data() + pos, v, n);
}

void ByteReader::fail(const std::string& problem) const { throw InputError(context_ + ": " + problem); }

uint64_t ByteReader::le(int n, const char* what) {
  if (remaining() < size_t(n)) fail(std::string(what) + " truncated");
  const uint64_t v = get_le(data_.data() + pos_, n);
  pos_ += size_t(n);
  return v;
}

uint8_t ByteReader::u8(const char* what) { return uint8_t(le(1, what)); }
uint16_t ByteReader::u16(const char* what) { return uint16_t(le(2, what)); }
uint32_t ByteReader::u32(const char* what) { return uint32_t(le(4, what)); }
uint64_t ByteReader::u64(const char* what) { return le(8, what); }

std::span<const uint8_t> ByteReader::bytes(size_t n, const char* what) {
  if (remaining() < n)
    fail(std::string(what) + " truncated (" + std::to_string(n) + " bytes claimed, " + std::to_string(remaining()) +
         " left)");
  const auto out = data_.subspan(pos_, n);
  pos_ += n;
  return out;
}

std::string ByteReader::string(const char* what) {
  const uint32_t n = u32(what);
  const auto b = bytes(n, what);
  return std::string(b.begin(), b.end());
}

std::map<std::string, std::string> ByteReader::string_map(const char* what) {
  const uint32_t n = u32(what);
  ByteReader inner(bytes(n, what), context_);
  std::map<std::string, std::string> out;
  while (inner.remaining() > 0) {
    std::string key = inner.string(what);
    out[key] = inner.string(what);
  }
  return out;
}

}  // namespace lidarloop
