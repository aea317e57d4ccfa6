#include "logs/mcap/mcap_reader.hpp"

#include <algorithm>

#include "common/input_error.hpp"
#include "logs/mcap/zstd_codec.hpp"

namespace lidarloop {

std::vector<uint8_t> chunk_records(const mcap::Chunk& chunk, const std::string& context) {
  std::vector<uint8_t> records;
  if (chunk.compression == "zstd") {
    records = zstd_decompress(chunk.records, chunk.uncompressed_size, context);
  } else if (chunk.compression.empty()) {
    if (chunk.records.size() != chunk.uncompressed_size)
      throw InputError(context + ": uncompressed chunk of " + std::to_string(chunk.records.size()) +
                       " bytes declares " + std::to_string(chunk.uncompressed_size));
    records.assign(chunk.records.begin(), chunk.records.end());
  } else {
    throw InputError(context + ": unsupported chunk compression '" + chunk.compression + "' (zstd or none)");
  }
  if (chunk.uncompressed_crc != 0 && crc32(records.data(), records.size()) != chunk.uncompressed_crc)
    throw InputError(context + ": chunk fails its CRC check (corrupt data)");
  return records;
}

McapReader::McapReader(const std::string& path) : stream_(path) { read_header(); }

McapReader::McapReader(std::FILE* stream, const std::string& name) : stream_(stream, name) { read_header(); }

void McapReader::read_header() {
  stream_.read_magic();
  stream_.next(record_);
  if (record_.opcode != uint8_t(mcap::Op::header))
    throw InputError(stream_.where(record_.offset) + ": expected the Header record, found " +
                     mcap::op_name(record_.opcode));
  ByteReader in(record_.content, stream_.where(record_.offset));
  header_ = mcap::parse_header(in);
}

void McapReader::read_schema(ByteReader& in) {
  mcap::Schema s = mcap::parse_schema(in);
  if (s.id == 0) return;  // invalid by the spec; readers ignore it
  const auto [it, added] = schemas_.emplace(s.id, s);
  if (!added && (it->second.name != s.name || it->second.encoding != s.encoding || it->second.data != s.data))
    in.fail("schema " + std::to_string(s.id) + " is defined twice, differently");
}

void McapReader::read_channel(ByteReader& in) {
  mcap::Channel c = mcap::parse_channel(in);
  if (c.schema_id != 0 && !schemas_.count(c.schema_id))
    in.fail("channel '" + c.topic + "' refers to undefined schema " + std::to_string(c.schema_id));
  const auto [it, added] = channels_.emplace(c.id, c);
  if (!added && (it->second.schema_id != c.schema_id || it->second.topic != c.topic ||
                 it->second.message_encoding != c.message_encoding || it->second.metadata != c.metadata))
    in.fail("channel " + std::to_string(c.id) + " is defined twice, differently");
}

void McapReader::read_message(ByteReader& in, McapMessage& out) {
  const mcap::MessageHeader h = mcap::parse_message_header(in);
  const auto channel = channels_.find(h.channel_id);
  if (channel == channels_.end()) in.fail("message on undefined channel " + std::to_string(h.channel_id));
  out.channel = &channel->second;
  out.schema = channel->second.schema_id ? &schemas_.at(channel->second.schema_id) : nullptr;
  out.sequence = h.sequence;
  out.log_time = h.log_time;
  out.publish_time = h.publish_time;
  out.data = in.rest();
}

void McapReader::load_chunk(const McapRecord& record) {
  const std::string context = stream_.where(record.offset) + " (Chunk)";
  ByteReader in(record.content, context);
  const mcap::Chunk chunk = mcap::parse_chunk(in);
  chunk_ = chunk_records(chunk, context);
  chunk_pos_ = 0;
  chunk_offset_ = record.offset;
  ++chunks_;
}

bool McapReader::next_in_chunk(McapMessage& out) {
  while (chunk_pos_ < chunk_.size()) {
    const std::string context = stream_.where(chunk_offset_) + " (Chunk), record at " + std::to_string(chunk_pos_);
    ByteReader prefix(std::span<const uint8_t>(chunk_).subspan(chunk_pos_), context);
    const uint8_t opcode = prefix.u8("record opcode");
    const uint64_t length = prefix.u64("record length");
    if (length > prefix.remaining())
      prefix.fail(std::string(mcap::op_name(opcode)) + " record overruns the chunk (" + std::to_string(length) +
                  " bytes claimed, " + std::to_string(prefix.remaining()) + " left)");
    ByteReader in(prefix.bytes(size_t(length), "record"), context);
    chunk_pos_ += 9 + size_t(length);
    switch (mcap::Op(opcode)) {
      case mcap::Op::schema:
        read_schema(in);
        break;
      case mcap::Op::channel:
        read_channel(in);
        break;
      case mcap::Op::message:
        read_message(in, out);
        return true;
      default:
        if (opcode < 0x80) in.fail(std::string("unexpected ") + mcap::op_name(opcode) + " record inside a chunk");
        break;  // 0x80-0xFF: application records, skipped
    }
  }
  chunk_.clear();
  chunk_pos_ = 0;
  return false;
}

bool McapReader::next(McapMessage& out) {
  while (!done_) {
    if (next_in_chunk(out)) return true;
    const uint32_t crc_before = stream_.crc();
    stream_.next(record_);
    const std::string context = stream_.where(record_.offset) + " (" + mcap::op_name(record_.opcode) + ")";
    ByteReader in(record_.content, context);
    switch (mcap::Op(record_.opcode)) {
      case mcap::Op::schema:
        read_schema(in);
        break;
      case mcap::Op::channel:
        read_channel(in);
        break;
      case mcap::Op::message:
        read_message(in, out);
        return true;
      case mcap::Op::chunk:
        load_chunk(record_);
        break;
      case mcap::Op::message_index:
        mcap::parse_message_index(in);
        break;
      case mcap::Op::attachment:
        attachments_.push_back(mcap::parse_attachment(in));
        break;
      case mcap::Op::metadata:
        metadata_.push_back(mcap::parse_metadata(in));
        break;
      case mcap::Op::data_end: {
        const uint32_t stored = mcap::parse_data_end(in);
        if (stored != 0 && stored != crc_before) in.fail("data section fails its CRC check (corrupt file)");
        finish();
        done_ = true;
        break;
      }
      case mcap::Op::header:
      case mcap::Op::footer:
        in.fail("unexpected record in the data section (is Data End missing?)");
      default:
        // Summary records do not belong here, but are harmless; unknown opcodes are future or
        // application records, which readers must skip.
        break;
    }
  }
  return false;
}

void McapReader::finish() {
  const uint64_t summary_start = stream_.position();
  stream_.reset_crc();
  while (true) {
    const uint32_t crc_before = stream_.crc();
    stream_.next(record_);
    const std::string context = stream_.where(record_.offset) + " (" + mcap::op_name(record_.opcode) + ")";
    ByteReader in(record_.content, context);
    switch (mcap::Op(record_.opcode)) {
      case mcap::Op::schema:
        mcap::parse_schema(in);
        break;
      case mcap::Op::channel:
        mcap::parse_channel(in);
        break;
      case mcap::Op::statistics:
        mcap::parse_statistics(in);
        break;
      case mcap::Op::chunk_index:
        mcap::parse_chunk_index(in);
        break;
      case mcap::Op::attachment_index:
        mcap::parse_attachment_index(in);
        break;
      case mcap::Op::metadata_index:
        mcap::parse_metadata_index(in);
        break;
      case mcap::Op::summary_offset:
        mcap::parse_summary_offset(in);
        break;
      case mcap::Op::footer: {
        const mcap::Footer footer = mcap::parse_footer(in);
        if (footer.summary_start != 0 && footer.summary_start != summary_start)
          in.fail("footer puts the summary at byte " + std::to_string(footer.summary_start) + ", not " +
                  std::to_string(summary_start));
        if (footer.summary_crc != 0) {
          // Summary CRC: from the summary's start through the footer's fields before the CRC.
          Crc32 crc = Crc32::resume(crc_before);
          const auto prefix = stream_.peek(record_.offset, 9);
          crc.update(prefix.data(), prefix.size());
          crc.update(record_.content.data(), 16);
          if (crc.value() != footer.summary_crc) in.fail("summary fails its CRC check (corrupt file)");
        }
        stream_.read_trailing_magic();
        return;
      }
      default:
        if (record_.opcode < 0x80 && record_.opcode != 0)
          in.fail(std::string("unexpected ") + mcap::op_name(record_.opcode) + " record in the summary");
        break;
    }
  }
}

std::optional<McapSummary> read_mcap_summary(const std::string& path) {
  McapRecordStream stream(path);
  stream.read_magic();
  const uint64_t size = stream.file_size();
  const uint64_t footer_at = size >= 8 + 29 + 8 ? size - 8 - 29 : 0;
  const auto tail = stream.peek(footer_at, 29 + 8);
  if (footer_at < 8 || !std::equal(tail.end() - 8, tail.end(), mcap::kMagic.begin()) ||
      tail[0] != uint8_t(mcap::Op::footer))
    throw InputError(path +
                     ": no footer at the end of the file: the log is truncated or was not closed "
                     "(lidarloop recover can rebuild it)");
  stream.seek(footer_at);
  McapRecord record;
  stream.next(record);
  ByteReader footer_in(record.content, stream.where(footer_at) + " (Footer)");
  const mcap::Footer footer = mcap::parse_footer(footer_in);
  if (footer.summary_start == 0) return std::nullopt;
  if (footer.summary_start < 8 || footer.summary_start > footer_at ||
      (footer.summary_offset_start != 0 &&
       (footer.summary_offset_start < footer.summary_start || footer.summary_offset_start > footer_at)))
    footer_in.fail("summary offsets point outside the file");

  if (footer_at - footer.summary_start > McapRecordStream::max_content(0))
    footer_in.fail("summary of " + std::to_string(footer_at - footer.summary_start) + " bytes is implausibly large");
  const auto summary = stream.peek(footer.summary_start, size_t(footer_at - footer.summary_start));
  if (footer.summary_crc != 0) {
    Crc32 crc;
    crc.update(summary.data(), summary.size());
    crc.update(tail.data(), 9 + 16);
    if (crc.value() != footer.summary_crc) footer_in.fail("summary fails its CRC check (corrupt file)");
  }

  McapSummary out;
  const uint64_t end = footer.summary_offset_start ? footer.summary_offset_start : footer_at;
  stream.seek(footer.summary_start);
  while (stream.position() < end) {
    stream.next(record);
    if (stream.position() > end)
      throw InputError(stream.where(record.offset) + ": summary record overruns its section");
    ByteReader in(record.content, stream.where(record.offset) + " (" + mcap::op_name(record.opcode) + ")");
    switch (mcap::Op(record.opcode)) {
      case mcap::Op::schema: {
        mcap::Schema s = mcap::parse_schema(in);
        out.schemas[s.id] = std::move(s);
        break;
      }
      case mcap::Op::channel: {
        mcap::Channel c = mcap::parse_channel(in);
        out.channels[c.id] = std::move(c);
        break;
      }
      case mcap::Op::statistics:
        out.statistics = mcap::parse_statistics(in);
        break;
      case mcap::Op::chunk_index:
        out.chunk_indexes.push_back(mcap::parse_chunk_index(in));
        break;
      case mcap::Op::attachment_index:
        out.attachment_indexes.push_back(mcap::parse_attachment_index(in));
        break;
      case mcap::Op::metadata_index:
        out.metadata_indexes.push_back(mcap::parse_metadata_index(in));
        break;
      default:
        break;
    }
  }
  return out;
}

}  // namespace lidarloop
