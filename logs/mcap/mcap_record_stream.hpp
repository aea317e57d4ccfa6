#pragma once
// The records of an MCAP file, one at a time in file order, straight from disk. Every length is
// checked against what is left of the file (and a per-record ceiling) before anything is allocated,
// so a truncated or corrupt file gives an InputError naming the file, the byte offset and the
// problem, never a huge allocation or a read past the end.
//
// It also reads a stream that cannot seek (a pipe, stdin): records then come strictly in order, a
// length is checked only against the ceiling, and the end is wherever the stream ends.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "common/crc32.hpp"

namespace lidarloop {

struct McapRecord {
  uint8_t opcode = 0;
  uint64_t offset = 0;           // of the opcode byte, from the start of the file
  std::vector<uint8_t> content;  // without the 9-byte prefix
  uint64_t size() const { return 9 + content.size(); }
};

class McapRecordStream {
 public:
  explicit McapRecordStream(const std::string& path);  // InputError if it cannot be opened
  // Reads `stream` (not owned, not closed) from where it is, in order; `name` is for messages.
  McapRecordStream(std::FILE* stream, const std::string& name);
  ~McapRecordStream();
  McapRecordStream(const McapRecordStream&) = delete;
  McapRecordStream& operator=(const McapRecordStream&) = delete;

  // Checks the leading magic; InputError "not an MCAP file" or "truncated" otherwise.
  void read_magic();
  // Reads the record at the current position and moves past it. On InputError the position and CRC
  // are unchanged.
  void next(McapRecord& out);
  // The 8 bytes at the current position must be the trailing magic and the end of the file.
  void read_trailing_magic();

  // A file only.
  void seek(uint64_t offset);
  // Up to n bytes at `offset` (fewer at the end of the file); does not move the position. On a
  // stream, only the 9-byte prefix of the record read last.
  std::vector<uint8_t> peek(uint64_t offset, size_t n);

  uint64_t position() const { return position_; }
  uint64_t file_size() const { return size_; }  // a stream: unknown, the largest uint64_t
  uint64_t remaining() const { return size_ - position_; }
  const std::string& path() const { return path_; }
  // Where the reader is, for messages: "FILE: byte N".
  std::string where(uint64_t offset) const;

  // CRC of every byte read through read_magic() and next() since the last reset_crc().
  uint32_t crc() const { return crc_.value(); }
  void reset_crc() { crc_ = Crc32(); }

  // Largest record content accepted, whatever the file size: chunks, messages and attachments may
  // be big; index and definition records are small.
  static uint64_t max_content(uint8_t opcode);

 private:
  void read_exact(uint64_t offset, void* dst, size_t n);

  std::string path_;
  std::FILE* file_ = nullptr;
  bool owned_ = true, seekable_ = true;
  uint64_t size_ = 0, position_ = 0;
  uint64_t read_position_ = 0;  // a stream's: where the next byte comes from
  uint64_t last_offset_ = 0;    // the record read last and its prefix (peek on a stream)
  uint8_t last_prefix_[9] = {};
  Crc32 crc_;
};

}  // namespace lidarloop
