#include "logs/mcap/mcap_records.hpp"

#include "common/crc32.hpp"

namespace lidarloop::mcap {

namespace {

// Writes the opcode and a placeholder length; the destructor fills in the content length.
class Record {
 public:
  Record(ByteWriter& out, Op op) : out_(out) {
    out_.u8(uint8_t(op));
    length_at_ = out_.size();
    out_.u64(0);
  }
  ~Record() { out_.patch_u64(length_at_, uint64_t(out_.size() - length_at_ - 8)); }
  Record(const Record&) = delete;
  Record& operator=(const Record&) = delete;

 private:
  ByteWriter& out_;
  size_t length_at_;
};

template <class Key>
void id_map(ByteWriter& out, const std::map<Key, uint64_t>& m) {
  out.u32(uint32_t(m.size() * (sizeof(Key) + 8)));
  for (const auto& [key, value] : m) {
    if constexpr (sizeof(Key) == 2) out.u16(key);
    out.u64(value);
  }
}

std::map<uint16_t, uint64_t> parse_id_map(ByteReader& in, const char* what) {
  const uint32_t n = in.u32(what);
  if (n % 10 != 0) in.fail(std::string(what) + ": byte length " + std::to_string(n) + " is not a multiple of 10");
  ByteReader inner(in.bytes(n, what), in.context());
  std::map<uint16_t, uint64_t> out;
  while (inner.remaining() > 0) {
    const uint16_t key = inner.u16(what);
    out[key] = inner.u64(what);
  }
  return out;
}

}  // namespace

const char* op_name(uint8_t opcode) {
  static constexpr const char* names[] = {"",           "Header",        "Footer",          "Schema",
                                          "Channel",    "Message",       "Chunk",           "MessageIndex",
                                          "ChunkIndex", "Attachment",    "AttachmentIndex", "Statistics",
                                          "Metadata",   "MetadataIndex", "SummaryOffset",   "DataEnd"};
  return opcode >= 1 && opcode <= 0x0F ? names[opcode] : "unknown";
}

void append(ByteWriter& out, const Header& r) {
  Record rec(out, Op::header);
  out.string(r.profile);
  out.string(r.library);
}

void append(ByteWriter& out, const Footer& r) {
  Record rec(out, Op::footer);
  out.u64(r.summary_start);
  out.u64(r.summary_offset_start);
  out.u32(r.summary_crc);
}

void append(ByteWriter& out, const Schema& r) {
  Record rec(out, Op::schema);
  out.u16(r.id);
  out.string(r.name);
  out.string(r.encoding);
  out.string(r.data);  // uint32-prefixed bytes: the same framing as a string
}

void append(ByteWriter& out, const Channel& r) {
  Record rec(out, Op::channel);
  out.u16(r.id);
  out.u16(r.schema_id);
  out.string(r.topic);
  out.string(r.message_encoding);
  out.string_map(r.metadata);
}

void append(ByteWriter& out, const MessageHeader& r, std::span<const uint8_t> data) {
  Record rec(out, Op::message);
  out.u16(r.channel_id);
  out.u32(r.sequence);
  out.u64(r.log_time);
  out.u64(r.publish_time);
  out.bytes(data);
}

void append(ByteWriter& out, const Chunk& r) {
  Record rec(out, Op::chunk);
  out.u64(r.message_start_time);
  out.u64(r.message_end_time);
  out.u64(r.uncompressed_size);
  out.u32(r.uncompressed_crc);
  out.string(r.compression);
  out.u64(r.records.size());
  out.bytes(r.records);
}

void append(ByteWriter& out, const MessageIndex& r) {
  Record rec(out, Op::message_index);
  out.u16(r.channel_id);
  out.u32(uint32_t(r.entries.size() * 16));
  for (const auto& [time, offset] : r.entries) {
    out.u64(time);
    out.u64(offset);
  }
}

void append(ByteWriter& out, const ChunkIndex& r) {
  Record rec(out, Op::chunk_index);
  out.u64(r.message_start_time);
  out.u64(r.message_end_time);
  out.u64(r.chunk_start_offset);
  out.u64(r.chunk_length);
  id_map(out, r.message_index_offsets);
  out.u64(r.message_index_length);
  out.string(r.compression);
  out.u64(r.compressed_size);
  out.u64(r.uncompressed_size);
}

void append(ByteWriter& out, const Attachment& r) {
  Record rec(out, Op::attachment);
  const size_t start = out.size();
  out.u64(r.log_time);
  out.u64(r.create_time);
  out.string(r.name);
  out.string(r.media_type);
  out.u64(r.data.size());
  out.bytes(r.data);
  out.u32(crc32(out.buffer().data() + start, out.size() - start));
}

void append(ByteWriter& out, const AttachmentIndex& r) {
  Record rec(out, Op::attachment_index);
  out.u64(r.offset);
  out.u64(r.length);
  out.u64(r.log_time);
  out.u64(r.create_time);
  out.u64(r.data_size);
  out.string(r.name);
  out.string(r.media_type);
}

void append(ByteWriter& out, const Statistics& r) {
  Record rec(out, Op::statistics);
  out.u64(r.message_count);
  out.u16(r.schema_count);
  out.u32(r.channel_count);
  out.u32(r.attachment_count);
  out.u32(r.metadata_count);
  out.u32(r.chunk_count);
  out.u64(r.message_start_time);
  out.u64(r.message_end_time);
  id_map(out, r.channel_message_counts);
}

void append(ByteWriter& out, const Metadata& r) {
  Record rec(out, Op::metadata);
  out.string(r.name);
  out.string_map(r.metadata);
}

void append(ByteWriter& out, const MetadataIndex& r) {
  Record rec(out, Op::metadata_index);
  out.u64(r.offset);
  out.u64(r.length);
  out.string(r.name);
}

void append(ByteWriter& out, const SummaryOffset& r) {
  Record rec(out, Op::summary_offset);
  out.u8(r.group_opcode);
  out.u64(r.group_start);
  out.u64(r.group_length);
}

void append_data_end(ByteWriter& out, uint32_t data_section_crc) {
  Record rec(out, Op::data_end);
  out.u32(data_section_crc);
}

Header parse_header(ByteReader& in) {
  Header r;
  r.profile = in.string("Header profile");
  r.library = in.string("Header library");
  return r;
}

Footer parse_footer(ByteReader& in) {
  Footer r;
  r.summary_start = in.u64("Footer summary_start");
  r.summary_offset_start = in.u64("Footer summary_offset_start");
  r.summary_crc = in.u32("Footer summary_crc");
  return r;
}

Schema parse_schema(ByteReader& in) {
  Schema r;
  r.id = in.u16("Schema id");
  r.name = in.string("Schema name");
  r.encoding = in.string("Schema encoding");
  r.data = in.string("Schema data");
  return r;
}

Channel parse_channel(ByteReader& in) {
  Channel r;
  r.id = in.u16("Channel id");
  r.schema_id = in.u16("Channel schema_id");
  r.topic = in.string("Channel topic");
  r.message_encoding = in.string("Channel message_encoding");
  r.metadata = in.string_map("Channel metadata");
  return r;
}

MessageHeader parse_message_header(ByteReader& in) {
  MessageHeader r;
  r.channel_id = in.u16("Message channel_id");
  r.sequence = in.u32("Message sequence");
  r.log_time = in.u64("Message log_time");
  r.publish_time = in.u64("Message publish_time");
  return r;
}

Chunk parse_chunk(ByteReader& in) {
  Chunk r;
  r.message_start_time = in.u64("Chunk message_start_time");
  r.message_end_time = in.u64("Chunk message_end_time");
  r.uncompressed_size = in.u64("Chunk uncompressed_size");
  r.uncompressed_crc = in.u32("Chunk uncompressed_crc");
  r.compression = in.string("Chunk compression");
  const uint64_t n = in.u64("Chunk records length");
  if (n > in.remaining())
    in.fail("Chunk records truncated (" + std::to_string(n) + " bytes claimed, " + std::to_string(in.remaining()) +
            " left)");
  r.records = in.bytes(size_t(n), "Chunk records");
  return r;
}

MessageIndex parse_message_index(ByteReader& in) {
  MessageIndex r;
  r.channel_id = in.u16("MessageIndex channel_id");
  const uint32_t n = in.u32("MessageIndex records");
  if (n % 16 != 0) in.fail("MessageIndex records: byte length " + std::to_string(n) + " is not a multiple of 16");
  ByteReader inner(in.bytes(n, "MessageIndex records"), in.context());
  r.entries.reserve(n / 16);
  while (inner.remaining() > 0) {
    const uint64_t time = inner.u64("MessageIndex log_time");
    r.entries.emplace_back(time, inner.u64("MessageIndex offset"));
  }
  return r;
}

ChunkIndex parse_chunk_index(ByteReader& in) {
  ChunkIndex r;
  r.message_start_time = in.u64("ChunkIndex message_start_time");
  r.message_end_time = in.u64("ChunkIndex message_end_time");
  r.chunk_start_offset = in.u64("ChunkIndex chunk_start_offset");
  r.chunk_length = in.u64("ChunkIndex chunk_length");
  r.message_index_offsets = parse_id_map(in, "ChunkIndex message_index_offsets");
  r.message_index_length = in.u64("ChunkIndex message_index_length");
  r.compression = in.string("ChunkIndex compression");
  r.compressed_size = in.u64("ChunkIndex compressed_size");
  r.uncompressed_size = in.u64("ChunkIndex uncompressed_size");
  return r;
}

Attachment parse_attachment(ByteReader& in) {
  const size_t start = in.offset();
  const auto content = in.rest();
  Attachment r;
  r.log_time = in.u64("Attachment log_time");
  r.create_time = in.u64("Attachment create_time");
  r.name = in.string("Attachment name");
  r.media_type = in.string("Attachment media_type");
  const uint64_t n = in.u64("Attachment data length");
  if (n > in.remaining()) in.fail("Attachment '" + r.name + "' data truncated");
  const auto data = in.bytes(size_t(n), "Attachment data");
  const uint32_t computed = crc32(content.data(), in.offset() - start);
  const uint32_t stored = in.u32("Attachment crc");
  if (stored != 0 && stored != computed) in.fail("Attachment '" + r.name + "' fails its CRC check");
  r.data.assign(data.begin(), data.end());
  return r;
}

AttachmentIndex parse_attachment_index(ByteReader& in) {
  AttachmentIndex r;
  r.offset = in.u64("AttachmentIndex offset");
  r.length = in.u64("AttachmentIndex length");
  r.log_time = in.u64("AttachmentIndex log_time");
  r.create_time = in.u64("AttachmentIndex create_time");
  r.data_size = in.u64("AttachmentIndex data_size");
  r.name = in.string("AttachmentIndex name");
  r.media_type = in.string("AttachmentIndex media_type");
  return r;
}

Statistics parse_statistics(ByteReader& in) {
  Statistics r;
  r.message_count = in.u64("Statistics message_count");
  r.schema_count = in.u16("Statistics schema_count");
  r.channel_count = in.u32("Statistics channel_count");
  r.attachment_count = in.u32("Statistics attachment_count");
  r.metadata_count = in.u32("Statistics metadata_count");
  r.chunk_count = in.u32("Statistics chunk_count");
  r.message_start_time = in.u64("Statistics message_start_time");
  r.message_end_time = in.u64("Statistics message_end_time");
  r.channel_message_counts = parse_id_map(in, "Statistics channel_message_counts");
  return r;
}

Metadata parse_metadata(ByteReader& in) {
  Metadata r;
  r.name = in.string("Metadata name");
  r.metadata = in.string_map("Metadata metadata");
  return r;
}

MetadataIndex parse_metadata_index(ByteReader& in) {
  MetadataIndex r;
  r.offset = in.u64("MetadataIndex offset");
  r.length = in.u64("MetadataIndex length");
  r.name = in.string("MetadataIndex name");
  return r;
}

SummaryOffset parse_summary_offset(ByteReader& in) {
  SummaryOffset r;
  r.group_opcode = in.u8("SummaryOffset group_opcode");
  r.group_start = in.u64("SummaryOffset group_start");
  r.group_length = in.u64("SummaryOffset group_length");
  return r;
}

uint32_t parse_data_end(ByteReader& in) { return in.u32("DataEnd data_section_crc"); }

}  // namespace lidarloop::mcap
