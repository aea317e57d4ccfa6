#pragma once
// zstd for MCAP chunks. Compression is single-threaded with a fixed level, so the same records give
// the same bytes on every run and thread count. Decompression trusts nothing in the input: the
// output buffer grows with what the frame really produces and stops at the size the chunk declares.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

struct ZSTD_CCtx_s;
struct ZSTD_DCtx_s;

namespace lidarloop {

class ZstdCompressor {
 public:
  explicit ZstdCompressor(int level);
  ~ZstdCompressor();
  ZstdCompressor(const ZstdCompressor&) = delete;
  ZstdCompressor& operator=(const ZstdCompressor&) = delete;

  // Replaces `out` with the compressed frame of `in`.
  void compress(std::span<const uint8_t> in, std::vector<uint8_t>& out);

 private:
  ZSTD_CCtx_s* ctx_;
  int level_;
};

// Decompresses one or more concatenated frames that must add up to exactly `expected_size` bytes
// (at most kMaxDecompressedSize); anything else throws InputError "<context>: ...".
inline constexpr uint64_t kMaxDecompressedSize = uint64_t(4) << 30;
std::vector<uint8_t> zstd_decompress(std::span<const uint8_t> in, uint64_t expected_size, const std::string& context);

}  // namespace lidarloop
