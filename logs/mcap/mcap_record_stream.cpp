#include "logs/mcap/mcap_record_stream.hpp"

#include <sys/stat.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "common/input_error.hpp"
#include "logs/mcap/mcap_records.hpp"

namespace lidarloop {

McapRecordStream::McapRecordStream(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw InputError(path + ": cannot open file (" + std::strerror(errno) + ")");
  struct stat st {};
  if (fstat(fileno(file_), &st) != 0 || !S_ISREG(st.st_mode)) {
    std::fclose(file_);
    throw InputError(path + ": not a regular file");
  }
  size_ = uint64_t(st.st_size);
}

McapRecordStream::McapRecordStream(std::FILE* stream, const std::string& name)
    : path_(name), file_(stream), owned_(false), seekable_(false), size_(UINT64_MAX) {}

McapRecordStream::~McapRecordStream() {
  if (file_ && owned_) std::fclose(file_);
}

std::string McapRecordStream::where(uint64_t offset) const { return path_ + ": byte " + std::to_string(offset); }

uint64_t McapRecordStream::max_content(uint8_t opcode) {
  switch (mcap::Op(opcode)) {
    case mcap::Op::chunk:
    case mcap::Op::message:
      return 1ull << 30;
    case mcap::Op::attachment:
      return 2ull << 30;
    default:
      return 64ull << 20;
  }
}

void McapRecordStream::read_exact(uint64_t offset, void* dst, size_t n) {
  if (n == 0) return;
  if (!seekable_) {
    if (offset != read_position_) throw std::logic_error("McapRecordStream: out-of-order read of a stream");
    const size_t got = std::fread(dst, 1, n, file_);
    read_position_ += got;
    if (got != n)
      throw InputError(where(offset) + ": the stream ended inside a record (" + std::to_string(got) + " of " +
                       std::to_string(n) + " bytes)");
    return;
  }
  if (fseeko(file_, off_t(offset), SEEK_SET) != 0 || std::fread(dst, 1, n, file_) != n)
    throw InputError(where(offset) + ": read failed (file changed while reading?)");
}

void McapRecordStream::read_magic() {
  uint8_t magic[8] = {};
  const size_t n = size_t(std::min<uint64_t>(8, size_));
  if (!seekable_ && std::fread(magic, 1, 8, file_) != 8)
    throw InputError(path_ + ": the stream ended inside the leading magic");
  if (!seekable_) read_position_ = 8;
  if (seekable_) read_exact(0, magic, n);
  if (std::memcmp(magic, mcap::kMagic.data(), n) != 0) throw InputError(path_ + ": not an MCAP file (bad magic)");
  if (n < 8) throw InputError(path_ + ": truncated inside the leading magic (" + std::to_string(size_) + " bytes)");
  crc_.update(magic, 8);
  position_ = 8;
}

void McapRecordStream::next(McapRecord& out) {
  if (remaining() < 9)
    throw InputError(where(position_) + ": truncated (" + std::to_string(remaining()) +
                     " bytes left, a record needs at least 9)");
  uint8_t prefix[9];
  read_exact(position_, prefix, 9);
  uint64_t length = 0;
  for (int i = 0; i < 8; ++i) length |= uint64_t(prefix[1 + i]) << (8 * i);
  const uint64_t left = remaining() - 9;
  if (length > left)
    throw InputError(where(position_) + ": truncated " + mcap::op_name(prefix[0]) + " record (" +
                     std::to_string(length) + " bytes claimed, " + std::to_string(left) + " left in the file)");
  if (length > max_content(prefix[0]))
    throw InputError(where(position_) + ": implausible " + mcap::op_name(prefix[0]) + " record length " +
                     std::to_string(length));
  out.opcode = prefix[0];
  out.offset = position_;
  last_offset_ = position_;
  std::memcpy(last_prefix_, prefix, 9);
  out.content.resize(size_t(length));
  read_exact(position_ + 9, out.content.data(), out.content.size());
  crc_.update(prefix, 9);
  crc_.update(out.content.data(), out.content.size());
  position_ += 9 + length;
}

void McapRecordStream::read_trailing_magic() {
  if (!seekable_) {
    uint8_t magic[8];
    read_exact(position_, magic, 8);
    if (std::memcmp(magic, mcap::kMagic.data(), 8) != 0) throw InputError(where(position_) + ": bad trailing magic");
    position_ += 8;
    if (std::fgetc(file_) != EOF) throw InputError(where(position_) + ": data after the trailing magic");
    return;
  }
  if (remaining() != 8)
    throw InputError(where(position_) + ": expected the trailing magic and the end of the file, found " +
                     std::to_string(remaining()) + " bytes");
  uint8_t magic[8];
  read_exact(position_, magic, 8);
  if (std::memcmp(magic, mcap::kMagic.data(), 8) != 0) throw InputError(where(position_) + ": bad trailing magic");
  position_ += 8;
}

void McapRecordStream::seek(uint64_t offset) {
  if (!seekable_) throw std::logic_error("McapRecordStream: seek on a stream");
  position_ = std::min(offset, size_);
}

std::vector<uint8_t> McapRecordStream::peek(uint64_t offset, size_t n) {
  if (offset == last_offset_ && n <= 9 && position_ > offset) return {last_prefix_, last_prefix_ + n};
  if (!seekable_) throw std::logic_error("McapRecordStream: peek on a stream");
  if (offset >= size_) return {};
  std::vector<uint8_t> out(size_t(std::min<uint64_t>(n, size_ - offset)));
  read_exact(offset, out.data(), out.size());
  return out;
}

}  // namespace lidarloop
