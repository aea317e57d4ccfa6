#pragma once
// Little-endian byte order, written out byte by byte, so files (MCAP logs, intensity map tiles) are the
// same on any host.
#include <cstddef>
#include <cstdint>

namespace lidarloop {

// Writes the low `n` bytes of `v` to out[0 .. n), least significant first.
template <class Byte>
void put_le(Byte* out, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out[i] = static_cast<Byte>(uint8_t(v >> (8 * i)));
}

// Appends the low `n` bytes of `v` to a byte container (std::string, std::vector<uint8_t>).
template <class Container>
void append_le(Container& out, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out.push_back(static_cast<typename Container::value_type>(uint8_t(v >> (8 * i))));
}

// Reads `n` bytes from in[0 .. n), least significant first.
template <class Byte>
uint64_t get_le(const Byte* in, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= uint64_t(static_cast<uint8_t>(in[i])) << (8 * i);
  return v;
}

}  // namespace lidarloop
