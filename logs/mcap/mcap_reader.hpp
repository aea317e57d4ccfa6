#pragma once
// Reads MCAP files written by McapWriter or any other writer that follows the specification.
//
// McapReader walks the data section in file order, the way a replay needs it: every chunk's CRC is
// checked before its messages are handed out, and at the end the data section's CRC, the summary's
// CRC, the footer and the trailing magic are checked too, so reaching the end means the whole file is
// intact. read_mcap_summary() reads only the footer and summary, for a quick look (`lidarloop info`).
//
// Anything malformed (truncated at any byte, flipped bits, absurd lengths) is an InputError naming
// the file, the byte offset and the problem. zstd and uncompressed chunks are supported; lz4 is not.
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "logs/mcap/mcap_record_stream.hpp"
#include "logs/mcap/mcap_records.hpp"

namespace lidarloop {

// One message; the pointers and the data stay valid until the next call to McapReader::next().
struct McapMessage {
  const mcap::Channel* channel = nullptr;
  const mcap::Schema* schema = nullptr;  // null when the channel has no schema
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;
  std::span<const uint8_t> data;
};

class McapReader {
 public:
  // Opens the file and reads the magic and the Header record.
  explicit McapReader(const std::string& path);
  // Reads a stream as it arrives (stdin, a pipe): next() blocks until the next message is there.
  // `stream` is not closed; `name` is for messages.
  McapReader(std::FILE* stream, const std::string& name);

  const std::string& path() const { return stream_.path(); }
  const mcap::Header& header() const { return header_; }

  // The next message in file order, or false once the whole file has been read and verified.
  bool next(McapMessage& out);

  // What the data section has defined so far (all of it once next() returned false).
  const std::map<uint16_t, mcap::Schema>& schemas() const { return schemas_; }
  const std::map<uint16_t, mcap::Channel>& channels() const { return channels_; }
  const std::vector<mcap::Attachment>& attachments() const { return attachments_; }
  const std::vector<mcap::Metadata>& metadata() const { return metadata_; }
  uint64_t chunks() const { return chunks_; }
  uint64_t position() const { return stream_.position(); }

 private:
  bool next_in_chunk(McapMessage& out);
  void read_schema(ByteReader& in);
  void read_channel(ByteReader& in);
  // The message record `in` (positioned at its content) on a known channel.
  void read_message(ByteReader& in, McapMessage& out);
  void load_chunk(const McapRecord& record);
  void read_header();
  void finish();  // after Data End: the summary, its CRC, the footer and the trailing magic

  McapRecordStream stream_;
  mcap::Header header_;
  McapRecord record_;
  std::map<uint16_t, mcap::Schema> schemas_;
  std::map<uint16_t, mcap::Channel> channels_;
  std::vector<mcap::Attachment> attachments_;
  std::vector<mcap::Metadata> metadata_;
  uint64_t chunks_ = 0;

  std::vector<uint8_t> chunk_;  // the decompressed records of the chunk being read
  size_t chunk_pos_ = 0;
  uint64_t chunk_offset_ = 0;
  bool done_ = false;
};

// The summary section, found through the footer.
struct McapSummary {
  std::map<uint16_t, mcap::Schema> schemas;
  std::map<uint16_t, mcap::Channel> channels;
  std::optional<mcap::Statistics> statistics;
  std::vector<mcap::ChunkIndex> chunk_indexes;
  std::vector<mcap::AttachmentIndex> attachment_indexes;
  std::vector<mcap::MetadataIndex> metadata_indexes;
};

// nullopt when the file is intact but has no summary; InputError when the file does not end with a
// valid footer and magic (a truncated file: `lidarloop recover` repairs it) or the summary is corrupt.
std::optional<McapSummary> read_mcap_summary(const std::string& path);

// Decompresses a chunk's records and checks their CRC; `context` names the file and the chunk.
std::vector<uint8_t> chunk_records(const mcap::Chunk& chunk, const std::string& context);

}  // namespace lidarloop
