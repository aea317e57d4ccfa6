#include "logs/mcap/zstd_codec.hpp"

#include <zstd.h>
#include <algorithm>
#include <memory>
#include <stdexcept>

#include "common/input_error.hpp"

namespace lidarloop {

ZstdCompressor::ZstdCompressor(int level) : ctx_(ZSTD_createCCtx()), level_(level) {
  if (!ctx_) throw std::bad_alloc();
}

ZstdCompressor::~ZstdCompressor() { ZSTD_freeCCtx(ctx_); }

void ZstdCompressor::compress(std::span<const uint8_t> in, std::vector<uint8_t>& out) {
  out.resize(ZSTD_compressBound(in.size()));
  const size_t n = ZSTD_compressCCtx(ctx_, out.data(), out.size(), in.data(), in.size(), level_);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
}

std::vector<uint8_t> zstd_decompress(std::span<const uint8_t> in, uint64_t expected_size, const std::string& context) {
  if (in.empty() && expected_size == 0) return {};
  if (expected_size > kMaxDecompressedSize)
    throw InputError(context + ": declares " + std::to_string(expected_size) + " bytes uncompressed, more than " +
                     std::to_string(kMaxDecompressedSize) + " (corrupt size field?)");
  std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!ctx) throw std::bad_alloc();
  // The declared size is only a claim: the buffer starts at no more than 16 MiB and grows with real
  // output, so a corrupt size field cannot make us allocate gigabytes. Room for one byte more than
  // declared tells "too long" apart from "exactly right".
  const uint64_t limit = expected_size + 1;
  std::vector<uint8_t> out(size_t(std::min<uint64_t>(limit, 16u << 20)));
  ZSTD_inBuffer src{in.data(), in.size(), 0};
  ZSTD_outBuffer dst{out.data(), out.size(), 0};
  size_t ret = 0;
  while (true) {
    const size_t in_before = src.pos, out_before = dst.pos;
    ret = ZSTD_decompressStream(ctx.get(), &dst, &src);
    if (ZSTD_isError(ret)) throw InputError(context + ": zstd data is corrupt (" + ZSTD_getErrorName(ret) + ")");
    if (dst.pos > expected_size)
      throw InputError(context + ": decompresses to more than the declared " + std::to_string(expected_size) +
                       " bytes");
    if (dst.pos == dst.size) {  // full: grow (never past the limit, which the check above guards)
      out.resize(size_t(std::min<uint64_t>(limit, uint64_t(out.size()) * 2)));
      dst.dst = out.data();
      dst.size = out.size();
      continue;
    }
    if (src.pos == src.size) break;  // all input used and the decoder had room: nothing more will come
    if (src.pos == in_before && dst.pos == out_before)
      throw InputError(context + ": zstd data is corrupt (no progress)");  // never loop forever
  }
  if (ret != 0) throw InputError(context + ": zstd data is truncated");
  if (dst.pos != expected_size)
    throw InputError(context + ": decompresses to " + std::to_string(dst.pos) + " bytes, not the declared " +
                     std::to_string(expected_size));
  out.resize(dst.pos);
  return out;
}

}  // namespace lidarloop
