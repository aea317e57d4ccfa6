#pragma once
// The file side of McapWriter: a queue of finished records and closed chunks, written to disk in the
// order they were queued by one worker thread (or inline), which also compresses the chunks, checks
// them with their CRCs, keeps the data section's CRC and records where each chunk, attachment and
// metadata record landed, for the summary.
//
// Doing all of this off the caller's thread leaves a simulation loop only the cost of serialising
// its messages. One writer thread and a FIFO keep the file's record order, and so every byte, the
// same as writing inline.
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "common/crc32.hpp"
#include "logs/mcap/mcap_records.hpp"
#include "logs/mcap/zstd_codec.hpp"

namespace lidarloop {

struct ClosedChunk {
  std::vector<uint8_t> records;                                                  // uncompressed Message records
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> index_entries;  // (log_time, offset)
  uint64_t start_time = 0, end_time = 0;
};

struct McapOutputTotals {
  uint64_t file_bytes = 0, chunks = 0, uncompressed_bytes = 0, compressed_bytes = 0;
};

class McapOutput {
 public:
  // Where bytes go instead of a file: a pipe to another program, say (see McapWriter's stream mode).
  using ByteSink = std::function<void(std::span<const uint8_t>)>;

  // Opens `path` for writing (InputError if it cannot). compression_level <= 0 with compress false
  // stores chunks uncompressed.
  McapOutput(const std::string& path, bool background, bool compress, int compression_level);
  // Hands every byte to `sink`, inline (no worker thread); `name` is for error messages.
  McapOutput(const std::string& name, ByteSink sink, bool compress, int compression_level);
  ~McapOutput();  // finishes what is queued, then closes the file; errors are swallowed here
  McapOutput(const McapOutput&) = delete;
  McapOutput& operator=(const McapOutput&) = delete;

  // Queue a whole record (or several) for the data section. `attachment` / `metadata`: an index to
  // complete with the record's offset and length.
  void write(std::vector<uint8_t> bytes, std::optional<mcap::AttachmentIndex> attachment = {},
             std::optional<mcap::MetadataIndex> metadata = {});
  // Queue a closed chunk: compressed, written with its message indexes, flushed to the operating
  // system. Blocks while the previous chunk is still being written: at most one closed chunk is ever
  // held in memory, which bounds both memory and what a killed process loses.
  void write(ClosedChunk chunk);
  // Waits until every queued chunk is written and flushed; rethrows the worker's first error.
  void wait_for_chunks();
  // A buffer a written chunk no longer needs (empty if none), to fill the next chunk without
  // allocating again.
  std::vector<uint8_t> spare_buffer();

  // Waits until everything queued is on disk; rethrows the first error the worker met.
  void drain();
  // drain(), then pushes the file's buffered bytes to the operating system.
  void flush();
  // After drain(): the data section's end, its CRC, and what the summary needs.
  uint64_t position() const { return position_; }
  uint32_t data_crc() const { return data_crc_.value(); }
  const std::vector<mcap::ChunkIndex>& chunk_indexes() const { return chunk_indexes_; }
  const std::vector<mcap::AttachmentIndex>& attachment_indexes() const { return attachment_indexes_; }
  const std::vector<mcap::MetadataIndex>& metadata_indexes() const { return metadata_indexes_; }
  McapOutputTotals totals() const;

  // After drain(): writes past the data section (Data End, summary, footer), then closes the file.
  void write_tail(const std::vector<uint8_t>& bytes);
  void close();

 private:
  struct Job {
    std::vector<uint8_t> bytes;
    std::optional<mcap::AttachmentIndex> attachment;
    std::optional<mcap::MetadataIndex> metadata;
    std::optional<ClosedChunk> chunk;
  };
  void push(Job job);
  void run();              // the worker thread
  void process(Job& job);  // on the worker (or inline): compress, write, index
  void emit(const uint8_t* data, size_t size, bool data_section);
  void rethrow();

  std::string path_;
  bool background_, compress_;
  ZstdCompressor compressor_;
  std::FILE* file_ = nullptr;
  ByteSink sink_;
  bool open_ = true;

  // Owned by whoever processes jobs: the worker while it runs, the caller after drain().
  uint64_t position_ = 0;
  Crc32 data_crc_;
  std::vector<uint8_t> compressed_;
  std::vector<mcap::ChunkIndex> chunk_indexes_;
  std::vector<mcap::AttachmentIndex> attachment_indexes_;
  std::vector<mcap::MetadataIndex> metadata_indexes_;

  // Shared, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  size_t queued_chunks_ = 0;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::vector<uint8_t> spare_;
  McapOutputTotals totals_;
  std::thread worker_;
};

}  // namespace lidarloop
