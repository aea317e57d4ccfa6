#include "logs/cdr.hpp"

#include <bit>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {
constexpr size_t kHeader = 4;  // encapsulation kind (2 bytes, big endian) + options
}

CdrWriter::CdrWriter() : buf_{0x00, 0x01, 0x00, 0x00} {}

CdrWriter::CdrWriter(std::vector<uint8_t>&& reuse) : buf_(std::move(reuse)) { buf_.assign({0x00, 0x01, 0x00, 0x00}); }

void CdrWriter::align(size_t n) {
  while ((buf_.size() - kHeader) % n != 0) buf_.push_back(0);
}

void CdrWriter::put(uint64_t v, size_t n) {
  align(n);
  for (size_t i = 0; i < n; ++i) buf_.push_back(uint8_t(v >> (8 * i)));
}

void CdrWriter::f32(float v) { put(std::bit_cast<uint32_t>(v), 4); }
void CdrWriter::f64(double v) { put(std::bit_cast<uint64_t>(v), 8); }

void CdrWriter::string(std::string_view s) {
  u32(uint32_t(s.size() + 1));
  buf_.insert(buf_.end(), s.begin(), s.end());
  buf_.push_back(0);
}

void CdrWriter::sequence_length(size_t n) { u32(uint32_t(n)); }

void CdrWriter::raw(std::span<const uint8_t> bytes) { buf_.insert(buf_.end(), bytes.begin(), bytes.end()); }

CdrReader::CdrReader(std::span<const uint8_t> data, std::string context) : data_(data), context_(std::move(context)) {
  if (data.size() < kHeader) fail("message shorter than its CDR header");
  if (data[0] != 0x00 || data[1] != 0x01)
    fail("unsupported CDR encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) +
         " (only little-endian CDR is read)");
}

void CdrReader::fail(const std::string& problem) const { throw InputError(context_ + ": " + problem); }

void CdrReader::align(size_t n) {
  const size_t pad = (n - (pos_ - kHeader) % n) % n;
  if (pad > remaining()) fail("message truncated");
  pos_ += pad;
}

uint64_t CdrReader::get(size_t n) {
  align(n);
  if (remaining() < n) fail("message truncated");
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v |= uint64_t(data_[pos_ + i]) << (8 * i);
  pos_ += n;
  return v;
}

float CdrReader::f32() { return std::bit_cast<float>(uint32_t(get(4))); }
double CdrReader::f64() { return std::bit_cast<double>(get(8)); }

std::string CdrReader::string() {
  const uint32_t n = u32();
  const auto bytes = raw(n);
  // The length counts the terminating NUL; tolerate writers that leave it out.
  const size_t chars = (!bytes.empty() && bytes.back() == 0) ? bytes.size() - 1 : bytes.size();
  return std::string(bytes.begin(), bytes.begin() + std::ptrdiff_t(chars));
}

uint32_t CdrReader::sequence_length(size_t element_size) {
  const uint32_t n = u32();
  if (element_size > 0 && uint64_t(n) * element_size > remaining())
    fail("sequence of " + std::to_string(n) + " elements is longer than the message");
  return n;
}

std::span<const uint8_t> CdrReader::raw(size_t n) {
  if (n > remaining()) fail("message truncated");
  const auto out = data_.subspan(pos_, n);
  pos_ += n;
  return out;
}

}  // namespace lidarloop
