#include "logs/mcap/mcap_output.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "common/input_error.hpp"
#include "logs/mcap/byte_io.hpp"

namespace lidarloop {

namespace {
// One closed chunk at a time: it is compressed and written while the caller fills the next, and the
// caller waits before queueing another, so a chunk is on disk before a newer one is queued.
constexpr size_t kMaxQueuedChunks = 1;
}  // namespace

McapOutput::McapOutput(const std::string& path, bool background, bool compress, int compression_level)
    : path_(path), background_(background), compress_(compress), compressor_(compression_level) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw InputError(path + ": cannot create file (" + std::strerror(errno) + ")");
  if (background_) worker_ = std::thread([this] { run(); });
}

McapOutput::McapOutput(const std::string& name, ByteSink sink, bool compress, int compression_level)
    : path_(name), background_(false), compress_(compress), compressor_(compression_level), sink_(std::move(sink)) {}

McapOutput::~McapOutput() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();  // finishes the queue: what was written stays readable
  if (file_) std::fclose(file_);
}

void McapOutput::rethrow() {
  if (error_) std::rethrow_exception(error_);
}

void McapOutput::push(Job job) {
  if (!background_) {
    process(job);
    return;
  }
  std::unique_lock lock(mutex_);
  rethrow();
  if (job.chunk) {
    changed_.wait(lock, [&] { return queued_chunks_ < kMaxQueuedChunks || error_; });
    rethrow();
    ++queued_chunks_;
  }
  queue_.push_back(std::move(job));
  changed_.notify_all();
}

void McapOutput::write(std::vector<uint8_t> bytes, std::optional<mcap::AttachmentIndex> attachment,
                       std::optional<mcap::MetadataIndex> metadata) {
  push({std::move(bytes), std::move(attachment), std::move(metadata), std::nullopt});
}

void McapOutput::write(ClosedChunk chunk) { push({{}, std::nullopt, std::nullopt, std::move(chunk)}); }

std::vector<uint8_t> McapOutput::spare_buffer() {
  std::lock_guard lock(mutex_);
  return std::exchange(spare_, {});
}

void McapOutput::run() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [&] { return !queue_.empty() || stopping_; });
    if (queue_.empty()) return;
    Job job = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    const bool failed = error_ != nullptr;
    lock.unlock();
    // After an error the queue is still emptied (producers must not wait forever), but not written.
    std::exception_ptr error;
    if (!failed) {
      try {
        process(job);
      } catch (...) {
        error = std::current_exception();
      }
    }
    lock.lock();
    if (error && !error_) error_ = error;
    busy_ = false;
    if (job.chunk) --queued_chunks_;
    changed_.notify_all();
  }
}

void McapOutput::wait_for_chunks() {
  if (!background_) return;
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queued_chunks_ == 0 || error_; });
  rethrow();
}

void McapOutput::drain() {
  if (!background_) return;
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.empty() && !busy_; });
  rethrow();
}

McapOutputTotals McapOutput::totals() const {
  std::lock_guard lock(mutex_);
  return totals_;
}

void McapOutput::emit(const uint8_t* data, size_t size, bool data_section) {
  if (!open_) throw std::logic_error("McapOutput: write after close()");
  if (sink_)
    sink_(std::span<const uint8_t>(data, size));
  else if (std::fwrite(data, 1, size, file_) != size)
    throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
  if (data_section) data_crc_.update(data, size);
  position_ += size;
  std::lock_guard lock(mutex_);
  totals_.file_bytes = position_;
}

void McapOutput::process(Job& job) {
  if (!job.chunk) {
    if (job.attachment) {
      job.attachment->offset = position_;
      job.attachment->length = job.bytes.size();
      attachment_indexes_.push_back(*job.attachment);
    }
    if (job.metadata) {
      job.metadata->offset = position_;
      job.metadata->length = job.bytes.size();
      metadata_indexes_.push_back(*job.metadata);
    }
    emit(job.bytes.data(), job.bytes.size(), true);
    return;
  }

  ClosedChunk& closed = *job.chunk;
  mcap::Chunk chunk;
  chunk.message_start_time = closed.start_time;
  chunk.message_end_time = closed.end_time;
  chunk.uncompressed_size = closed.records.size();
  chunk.uncompressed_crc = crc32(closed.records.data(), closed.records.size());
  if (compress_) {
    compressor_.compress(closed.records, compressed_);
    chunk.compression = "zstd";
    chunk.records = compressed_;
  } else {
    chunk.records = closed.records;
  }

  mcap::ChunkIndex index;
  index.message_start_time = chunk.message_start_time;
  index.message_end_time = chunk.message_end_time;
  index.chunk_start_offset = position_;
  index.compression = chunk.compression;
  index.compressed_size = chunk.records.size();
  index.uncompressed_size = chunk.uncompressed_size;
  ByteWriter out;
  mcap::append(out, chunk);
  index.chunk_length = out.size();
  const uint64_t indexes_start = position_ + out.size();
  for (auto& [channel_id, entries] : closed.index_entries) {
    // Readers binary-search these by time; file order breaks ties, so equal times keep their order.
    std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    index.message_index_offsets[channel_id] = position_ + out.size();
    mcap::append(out, mcap::MessageIndex{channel_id, entries});
  }
  index.message_index_length = position_ + out.size() - indexes_start;
  emit(out.buffer().data(), out.size(), true);
  // One flush per chunk: a killed process leaves whole chunks behind, at a cost of ~1 syscall/s.
  if (file_ && std::fflush(file_) != 0) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
  chunk_indexes_.push_back(std::move(index));

  std::lock_guard lock(mutex_);
  ++totals_.chunks;
  totals_.uncompressed_bytes += chunk.uncompressed_size;
  totals_.compressed_bytes += chunk.records.size();
  if (spare_.capacity() < closed.records.capacity()) spare_.swap(closed.records);
}

void McapOutput::write_tail(const std::vector<uint8_t>& bytes) { emit(bytes.data(), bytes.size(), false); }

void McapOutput::flush() {
  drain();
  if (file_ && std::fflush(file_) != 0) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

void McapOutput::close() {
  open_ = false;
  if (!file_) return;
  const int flush_failed = std::fflush(file_);
  const int close_failed = std::fclose(file_);
  file_ = nullptr;
  if (flush_failed || close_failed) throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

}  // namespace lidarloop
