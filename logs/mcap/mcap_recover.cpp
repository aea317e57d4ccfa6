#include "logs/mcap/mcap_recover.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>

#include "common/input_error.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/mcap/mcap_record_stream.hpp"

namespace lidarloop {

namespace {

// A chunk's records, decoded and CRC-checked, before anything of it is written: a chunk is kept whole
// or not at all.
struct ChunkContents {
  std::vector<uint8_t> records;
  struct Item {
    uint8_t opcode;
    size_t offset, length;  // of the content, in `records`
  };
  std::vector<Item> items;
};

std::optional<ChunkContents> decode_chunk(const McapRecord& record, const std::string& context,
                                          McapRecoverReport& report);

class Recovery {
 public:
  Recovery(McapRecordStream& in, McapWriter& out, McapRecoverReport& report) : in_(in), out_(out), report_(report) {}

  void run() {
    McapRecord record;
    while (in_.remaining() > 0) {
      const uint64_t at = in_.position();
      try {
        in_.next(record);
      } catch (const InputError& e) {
        problem(e.what());
        if (!resync(at + 1)) return;
        continue;
      }
      if (!handle(record)) return;
    }
  }

 private:
  void problem(const std::string& what) {
    if (report_.problems.size() < 20) report_.problems.push_back(what);
  }

  // Returns false at Data End.
  bool handle(const McapRecord& record) {
    const std::string context = in_.where(record.offset) + " (" + mcap::op_name(record.opcode) + ")";
    try {
      ByteReader in(record.content, context);
      switch (mcap::Op(record.opcode)) {
        case mcap::Op::schema:
          schema(in);
          break;
        case mcap::Op::channel:
          channel(in);
          break;
        case mcap::Op::message:
          message(in);
          break;
        case mcap::Op::chunk:
          if (auto chunk = decode_chunk(record, context, report_)) write_chunk(*chunk, context);
          break;
        case mcap::Op::attachment:
          out_.add_attachment(mcap::parse_attachment(in));
          ++report_.attachments;
          break;
        case mcap::Op::metadata: {
          const mcap::Metadata m = mcap::parse_metadata(in);
          out_.add_metadata(m.name, m.metadata);
          ++report_.metadata;
          break;
        }
        case mcap::Op::data_end:
          report_.complete = true;
          return false;
        case mcap::Op::message_index:
          break;  // rebuilt by the writer
        default:
          // Anything else has no place in a data section: the framing is off. Look for the next chunk.
          if (record.opcode < 0x80) {
            problem(context + ": unexpected record in the data section");
            return resync(record.offset + 1);
          }
          break;
      }
    } catch (const InputError& e) {
      problem(e.what());
    }
    return true;
  }

  void schema(ByteReader& in) {
    const mcap::Schema s = mcap::parse_schema(in);
    if (s.id == 0 || schema_ids_.count(s.id)) return;
    schema_ids_[s.id] = out_.add_schema(s.name, s.encoding, s.data);
  }

  void channel(ByteReader& in) {
    const mcap::Channel c = mcap::parse_channel(in);
    if (channel_ids_.count(c.id)) return;
    uint16_t schema_id = 0;
    if (c.schema_id != 0) {
      const auto it = schema_ids_.find(c.schema_id);
      if (it == schema_ids_.end()) in.fail("channel '" + c.topic + "' refers to a lost schema");
      schema_id = it->second;
    }
    channel_ids_[c.id] = out_.add_channel(schema_id, c.topic, c.message_encoding, c.metadata);
  }

  void message(ByteReader& in) {
    const mcap::MessageHeader h = mcap::parse_message_header(in);
    const auto it = channel_ids_.find(h.channel_id);
    if (it == channel_ids_.end()) {
      ++report_.orphan_messages;
      return;
    }
    out_.write_message(it->second, h.sequence, h.log_time, h.publish_time, in.rest());
    ++report_.messages;
  }

  void write_chunk(const ChunkContents& chunk, const std::string& context) {
    for (const auto& item : chunk.items) {
      ByteReader in(std::span<const uint8_t>(chunk.records).subspan(item.offset, item.length), context);
      switch (mcap::Op(item.opcode)) {
        case mcap::Op::schema:
          schema(in);
          break;
        case mcap::Op::channel:
          channel(in);
          break;
        case mcap::Op::message:
          message(in);
          break;
        default:
          break;
      }
    }
    ++report_.chunks;
  }

  // Scans forward from `from` for the next whole, CRC-checked chunk, keeps it and continues after it.
  // Returns false when none is left.
  bool resync(uint64_t from) {
    constexpr size_t kWindow = 1 << 20, kHead = 9 + 28 + 4 + 4 + 8;  // prefix, fixed fields, "zstd", length
    const uint64_t size = in_.file_size();
    for (uint64_t base = from; base < size; base += kWindow) {
      const auto buf = in_.peek(base, kWindow + kHead);
      for (size_t i = 0; i < std::min(kWindow, buf.size()); ++i) {
        if (buf[i] != uint8_t(mcap::Op::chunk) || i + kHead > buf.size()) continue;
        if (!plausible_chunk_head(buf.data() + i, size - (base + i))) continue;
        in_.seek(base + i);
        McapRecord record;
        try {
          in_.next(record);
        } catch (const InputError&) {
          continue;
        }
        McapRecoverReport scratch;  // a false start is not a skipped chunk
        auto chunk = decode_chunk(record, in_.where(record.offset) + " (Chunk)", scratch);
        if (!chunk) continue;
        report_.skipped_bytes += base + i - (from - 1);
        write_chunk(*chunk, in_.where(record.offset));
        return true;
      }
    }
    report_.skipped_bytes += size - (from - 1);
    in_.seek(size);
    return false;
  }

  static uint64_t le(const uint8_t* p, int n) {
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= uint64_t(p[i]) << (8 * i);
    return v;
  }

  // Cheap checks on a would-be chunk record before trying to decode it: a length that fits in the
  // file, a known compression, and a records length that adds up.
  static bool plausible_chunk_head(const uint8_t* p, uint64_t left) {
    const uint64_t length = le(p + 1, 8);
    if (length < 28 + 4 + 8 || length > left - 9) return false;
    const uint64_t name_length = le(p + 9 + 28, 4);
    if (name_length != 0 && !(name_length == 4 && std::memcmp(p + 9 + 28 + 4, "zstd", 4) == 0)) return false;
    const uint64_t records = le(p + 9 + 28 + 4 + name_length, 8);
    return records == length - (28 + 4 + name_length + 8);
  }

  McapRecordStream& in_;
  McapWriter& out_;
  McapRecoverReport& report_;
  std::map<uint16_t, uint16_t> schema_ids_, channel_ids_;  // input id -> output id
};

std::optional<ChunkContents> decode_chunk(const McapRecord& record, const std::string& context,
                                          McapRecoverReport& report) {
  try {
    ByteReader in(record.content, context);
    const mcap::Chunk chunk = mcap::parse_chunk(in);
    ChunkContents out;
    out.records = chunk_records(chunk, context);
    ByteReader records(out.records, context);
    while (records.remaining() > 0) {
      const uint8_t opcode = records.u8("record opcode");
      const uint64_t length = records.u64("record length");
      if (length > records.remaining()) records.fail("record overruns the chunk");
      out.items.push_back({opcode, records.offset(), size_t(length)});
      records.bytes(size_t(length), "record");
    }
    return out;
  } catch (const InputError& e) {
    ++report.skipped_chunks;
    if (report.problems.size() < 20) report.problems.push_back(e.what());
    return std::nullopt;
  }
}

}  // namespace

McapRecoverReport recover_mcap(const std::string& broken, const std::string& fixed, McapWriterOptions options) {
  std::error_code ec;
  if (std::filesystem::equivalent(broken, fixed, ec))
    throw InputError(fixed + ": recover writes a new file; give it a different name than the input");
  McapRecordStream in(broken);
  McapRecoverReport report;
  report.input_bytes = in.file_size();
  const auto magic = in.peek(0, 8);
  if (!std::equal(magic.begin(), magic.end(), mcap::kMagic.begin()))
    throw InputError(broken + ": not an MCAP file (bad magic)");

  McapRecord record;
  if (magic.size() == 8) {
    in.read_magic();
    try {
      in.next(record);
      if (record.opcode == uint8_t(mcap::Op::header)) {
        ByteReader header(record.content, in.where(record.offset) + " (Header)");
        options.profile = mcap::parse_header(header).profile;
      } else {
        in.seek(8);
      }
    } catch (const InputError&) {
      // Reported by the scan below, which starts at the same place and resynchronises.
    }
  }
  McapWriter out(fixed, options);
  if (magic.size() < 8) {
    report.problems.push_back(broken + ": truncated inside the leading magic");
    report.skipped_bytes = report.input_bytes;
  } else {
    Recovery(in, out, report).run();
  }
  out.close();
  return report;
}

}  // namespace lidarloop
