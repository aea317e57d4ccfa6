#pragma once
// Writes MCAP files (https://mcap.dev/spec): schemas and channels in the data section as they are
// registered, messages in zstd-compressed chunks each followed by one Message Index per channel, then
// Data End (with the data section's CRC), a summary (schemas, channels, statistics, chunk, attachment
// and metadata indexes), summary offsets and a footer with the summary's CRC.
//
// A chunk is closed when its uncompressed records reach `chunk_size` bytes or its messages span
// `chunk_duration_ns` of log time, and the file is flushed after every chunk. A process killed
// mid-run (SIGKILL, a crash) leaves every written chunk in the file, readable by `lidarloop
// recover`, and loses only what was still in memory: the open chunk and at most one closed chunk
// being compressed and written. Both are bounded in log time (the writer's clock, not the wall's:
// a simulation runs faster than real time): the open chunk spans less than chunk_duration_ns, and a
// message stamped 2 x chunk_duration_ns after the start of a closed chunk that is still being
// written waits until it is. So the messages a kill loses all lie within 2 x chunk_duration_ns
// (1 s by default) of log time before the newest message written. "Written" means handed to the
// operating system (fflush): a killed process loses nothing the kernel has; a power cut is another
// matter (no fsync, which would cost a disk round trip per chunk).
//
// Compression, CRCs and file writes happen on a worker thread (McapOutput), so the caller pays only
// for serialising its messages. The output depends only on what is written (no clocks, no
// addresses, ordered containers, single-threaded zstd per chunk, one FIFO to disk): the same calls
// give the same bytes, with or without the worker.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "logs/mcap/byte_io.hpp"
#include "logs/mcap/mcap_output.hpp"
#include "logs/mcap/mcap_records.hpp"

namespace lidarloop {

struct McapWriterOptions {
  std::string profile = "ros2";
  std::string library;                      // empty: "lidarloop <version>"
  bool compress = true;                     // zstd chunks; false stores them uncompressed
  int compression_level = 1;                // zstd: 1 is 2.3x faster than 3 on scans, for 5 % more bytes
  uint64_t chunk_size = 4u << 20;           // uncompressed bytes that close a chunk
  int64_t chunk_duration_ns = 500'000'000;  // log time a chunk may span: a kill loses at most twice this
  bool background = true;                   // compress and write on a worker thread (same bytes)
  // false: every message is a record of its own in the data section, readable the moment it is
  // written (a live stream to another program); no chunks, so no message indexes either.
  bool chunked = true;
};

struct McapWriterStats {
  uint64_t messages = 0, chunks = 0;
  uint64_t message_bytes = 0;       // payloads only
  uint64_t uncompressed_bytes = 0;  // chunk records before compression
  uint64_t compressed_bytes = 0;    // chunk records as stored
  uint64_t file_bytes = 0;          // on disk so far (the whole file after close())
};

class McapWriter {
 public:
  // Creates (truncates) `path` and writes the magic and Header. InputError if it cannot.
  explicit McapWriter(const std::string& path, McapWriterOptions options = {});
  // Writes to `sink` instead of a file (inline: `background` is ignored); `name` is for messages.
  McapWriter(const std::string& name, McapOutput::ByteSink sink, McapWriterOptions options = {});
  // Closes the file if close() was not called; errors are swallowed there, so call close().
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids start at 1 and count up in registration order.
  uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  uint16_t add_channel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                       const mcap::StringMap& metadata = {});

  // `sequence` counts messages per channel from 0 when not given.
  void write_message(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::span<const uint8_t> data);
  void write_message(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                     std::span<const uint8_t> data);

  void add_attachment(const mcap::Attachment& attachment);
  void add_metadata(const std::string& name, const mcap::StringMap& metadata);

  // Closes the open chunk and hands everything written so far to the file or sink: a reader at the
  // other end of a pipe then has every message up to here.
  void flush();

  // Writes the last chunk, Data End, the summary and the footer, and closes the file. Errors met by
  // the worker thread (a full disk) surface here, or at the next call after them.
  void close();
  bool closed() const { return output_ == nullptr; }

  const std::string& path() const { return path_; }
  McapWriterStats stats() const;

 private:
  void start();
  void emit(ByteWriter& bytes);
  void flush_chunk();
  void check_open(const char* what) const;
  std::vector<uint8_t> summary_and_footer(uint64_t summary_start);

  std::string path_;
  McapWriterOptions options_;
  std::unique_ptr<McapOutput> output_;

  std::vector<mcap::Schema> schemas_;
  std::vector<mcap::Channel> channels_;
  std::vector<uint32_t> next_sequence_;  // by channel id - 1

  // The open chunk.
  ByteWriter chunk_records_;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_entries_;
  uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  // The start of the last closed chunk, until it is known to be written.
  std::optional<uint64_t> queued_chunk_start_;

  mcap::Statistics statistics_;
  McapWriterStats stats_;
};

}  // namespace lidarloop
