#pragma once
// The MCAP records (https://mcap.dev/spec): their fields, how each is written into a buffer
// (opcode, uint64 content length, content), and how each is parsed from its content. Shared by the
// writer, the reader and `recover`, so the layout is spelled out once.
#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "logs/mcap/byte_io.hpp"

namespace lidarloop::mcap {

// 0x89 "MCAP" major version '0' "\r\n", at both ends of the file.
inline constexpr std::array<uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr size_t kRecordPrefix = 9;  // opcode + uint64 content length
inline constexpr size_t kFooterContent = 20;

enum class Op : uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};
const char* op_name(uint8_t opcode);  // "Chunk", ... or "unknown"

using StringMap = std::map<std::string, std::string>;

struct Header {
  std::string profile, library;
};

struct Footer {
  uint64_t summary_start = 0, summary_offset_start = 0;
  uint32_t summary_crc = 0;
};

struct Schema {
  uint16_t id = 0;
  std::string name, encoding, data;
};

struct Channel {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  StringMap metadata;
};

// A Message record's fixed fields; the payload is the rest of the record.
struct MessageHeader {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;
};
inline constexpr size_t kMessageHeaderSize = 22;

struct Chunk {
  uint64_t message_start_time = 0, message_end_time = 0, uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;
  std::string compression;
  std::span<const uint8_t> records;  // compressed as `compression` says; points into the parsed buffer
};

struct MessageIndex {
  uint16_t channel_id = 0;
  std::vector<std::pair<uint64_t, uint64_t>> entries;  // (log_time, offset in the uncompressed chunk)
};

struct ChunkIndex {
  uint64_t message_start_time = 0, message_end_time = 0, chunk_start_offset = 0, chunk_length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0, uncompressed_size = 0;
};

struct Attachment {
  uint64_t log_time = 0, create_time = 0;
  std::string name, media_type;
  std::vector<uint8_t> data;
};

struct AttachmentIndex {
  uint64_t offset = 0, length = 0, log_time = 0, create_time = 0, data_size = 0;
  std::string name, media_type;
};

struct Statistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
  uint64_t message_start_time = 0, message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};

struct Metadata {
  std::string name;
  StringMap metadata;
};

struct MetadataIndex {
  uint64_t offset = 0, length = 0;
  std::string name;
};

struct SummaryOffset {
  uint8_t group_opcode = 0;
  uint64_t group_start = 0, group_length = 0;
};

// Each appends one whole record (prefix and content) to `out`.
void append(ByteWriter& out, const Header& r);
void append(ByteWriter& out, const Footer& r);
void append(ByteWriter& out, const Schema& r);
void append(ByteWriter& out, const Channel& r);
void append(ByteWriter& out, const MessageHeader& r, std::span<const uint8_t> data);
void append(ByteWriter& out, const Chunk& r);
void append(ByteWriter& out, const MessageIndex& r);
void append(ByteWriter& out, const ChunkIndex& r);
void append(ByteWriter& out, const Attachment& r);  // computes the attachment's CRC
void append(ByteWriter& out, const AttachmentIndex& r);
void append(ByteWriter& out, const Statistics& r);
void append(ByteWriter& out, const Metadata& r);
void append(ByteWriter& out, const MetadataIndex& r);
void append(ByteWriter& out, const SummaryOffset& r);
void append_data_end(ByteWriter& out, uint32_t data_section_crc);

// Each parses a record's content (after the prefix). Malformed content throws InputError with the
// reader's context; fields added by later versions of the format are ignored, as the spec asks.
Header parse_header(ByteReader& in);
Footer parse_footer(ByteReader& in);
Schema parse_schema(ByteReader& in);
Channel parse_channel(ByteReader& in);
MessageHeader parse_message_header(ByteReader& in);  // leaves `in` at the payload
Chunk parse_chunk(ByteReader& in);
MessageIndex parse_message_index(ByteReader& in);
ChunkIndex parse_chunk_index(ByteReader& in);
Attachment parse_attachment(ByteReader& in);  // checks the attachment's CRC when it is not 0
AttachmentIndex parse_attachment_index(ByteReader& in);
Statistics parse_statistics(ByteReader& in);
Metadata parse_metadata(ByteReader& in);
MetadataIndex parse_metadata_index(ByteReader& in);
SummaryOffset parse_summary_offset(ByteReader& in);
uint32_t parse_data_end(ByteReader& in);

}  // namespace lidarloop::mcap
