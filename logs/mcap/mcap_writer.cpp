#include "logs/mcap/mcap_writer.hpp"

#include <algorithm>
#include <stdexcept>

#include "common/input_error.hpp"

#ifndef LIDARLOOP_VERSION
#define LIDARLOOP_VERSION "unknown"
#endif

namespace lidarloop {

McapWriter::McapWriter(const std::string& path, McapWriterOptions options) : path_(path), options_(std::move(options)) {
  output_ = std::make_unique<McapOutput>(path, options_.background, options_.compress, options_.compression_level);
  start();
}

McapWriter::McapWriter(const std::string& name, McapOutput::ByteSink sink, McapWriterOptions options)
    : path_(name), options_(std::move(options)) {
  output_ = std::make_unique<McapOutput>(name, std::move(sink), options_.compress, options_.compression_level);
  start();
}

void McapWriter::start() {
  if (options_.library.empty()) options_.library = std::string("lidarloop ") + LIDARLOOP_VERSION;
  if (options_.chunk_size == 0 || options_.chunk_duration_ns <= 0)
    throw std::invalid_argument("McapWriter: chunk size and duration must be positive");
  ByteWriter start;
  for (uint8_t b : mcap::kMagic) start.u8(b);
  mcap::append(start, mcap::Header{options_.profile, options_.library});
  emit(start);
  output_->flush();  // a file that cannot be written (a full disk) fails here, before any message
}

McapWriter::~McapWriter() {
  if (!output_) return;
  try {
    close();
  } catch (...) {
    // A destructor must not throw; whatever was flushed before stays readable by `recover`.
  }
  output_.reset();
}

void McapWriter::check_open(const char* what) const {
  if (!output_) throw std::logic_error(std::string("McapWriter::") + what + " after close()");
}

void McapWriter::emit(ByteWriter& bytes) { output_->write(std::move(bytes.buffer())); }

uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  check_open("add_schema");
  if (schemas_.size() >= 0xFFFF) throw std::length_error("McapWriter: too many schemas");
  mcap::Schema schema{uint16_t(schemas_.size() + 1), name, encoding, data};
  // Outside any chunk, before the chunk that first uses it: whatever happens to later chunks, every
  // reader (and `recover`) knows all schemas and channels.
  ByteWriter out;
  mcap::append(out, schema);
  emit(out);
  schemas_.push_back(std::move(schema));
  return schemas_.back().id;
}

uint16_t McapWriter::add_channel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                 const mcap::StringMap& metadata) {
  check_open("add_channel");
  if (schema_id > schemas_.size()) throw std::invalid_argument("McapWriter: unknown schema id");
  if (channels_.size() >= 0xFFFF) throw std::length_error("McapWriter: too many channels");
  mcap::Channel channel{uint16_t(channels_.size() + 1), schema_id, topic, message_encoding, metadata};
  ByteWriter out;
  mcap::append(out, channel);
  emit(out);
  channels_.push_back(std::move(channel));
  next_sequence_.push_back(0);
  statistics_.channel_message_counts[channels_.back().id] = 0;
  return channels_.back().id;
}

void McapWriter::write_message(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
                               std::span<const uint8_t> data) {
  if (channel_id == 0 || channel_id > channels_.size()) throw std::invalid_argument("McapWriter: unknown channel id");
  write_message(channel_id, next_sequence_[channel_id - 1], log_time, publish_time, data);
}

void McapWriter::write_message(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                               std::span<const uint8_t> data) {
  check_open("write_message");
  if (channel_id == 0 || channel_id > channels_.size()) throw std::invalid_argument("McapWriter: unknown channel id");
  if (options_.chunked) {
    const auto duration = uint64_t(options_.chunk_duration_ns);
    // The closed chunk still in memory may not hold messages older than 2 x duration: wait for it.
    if (queued_chunk_start_ && log_time >= *queued_chunk_start_ + 2 * duration) {
      output_->wait_for_chunks();
      queued_chunk_start_.reset();
    }
    if (!chunk_index_entries_.empty() &&
        std::max(chunk_end_time_, log_time) - std::min(chunk_start_time_, log_time) >= duration)
      flush_chunk();
    const bool first = chunk_index_entries_.empty();
    chunk_index_entries_[channel_id].emplace_back(log_time, chunk_records_.size());
    mcap::append(chunk_records_, mcap::MessageHeader{channel_id, sequence, log_time, publish_time}, data);
    chunk_start_time_ = first ? log_time : std::min(chunk_start_time_, log_time);
    chunk_end_time_ = first ? log_time : std::max(chunk_end_time_, log_time);
  } else {
    ByteWriter out;
    mcap::append(out, mcap::MessageHeader{channel_id, sequence, log_time, publish_time}, data);
    emit(out);
  }

  next_sequence_[channel_id - 1] = sequence + 1;
  statistics_.message_start_time =
      statistics_.message_count == 0 ? log_time : std::min(statistics_.message_start_time, log_time);
  statistics_.message_end_time =
      statistics_.message_count == 0 ? log_time : std::max(statistics_.message_end_time, log_time);
  ++statistics_.message_count;
  ++statistics_.channel_message_counts[channel_id];
  ++stats_.messages;
  stats_.message_bytes += data.size();

  if (chunk_records_.size() >= options_.chunk_size) flush_chunk();
}

void McapWriter::flush_chunk() {
  if (chunk_index_entries_.empty()) return;
  ClosedChunk chunk;
  chunk.records = std::move(chunk_records_.buffer());
  chunk.index_entries = std::move(chunk_index_entries_);
  chunk.start_time = chunk_start_time_;
  chunk.end_time = chunk_end_time_;
  chunk_records_.buffer() = output_->spare_buffer();
  chunk_records_.buffer().clear();
  chunk_index_entries_.clear();
  ++statistics_.chunk_count;
  queued_chunk_start_ = chunk.start_time;
  output_->write(std::move(chunk));
}

void McapWriter::flush() {
  check_open("flush");
  flush_chunk();
  output_->flush();
}

void McapWriter::add_attachment(const mcap::Attachment& attachment) {
  check_open("add_attachment");
  ByteWriter out;
  mcap::append(out, attachment);
  output_->write(std::move(out.buffer()),
                 mcap::AttachmentIndex{0, 0, attachment.log_time, attachment.create_time, attachment.data.size(),
                                       attachment.name, attachment.media_type});
  ++statistics_.attachment_count;
}

void McapWriter::add_metadata(const std::string& name, const mcap::StringMap& metadata) {
  check_open("add_metadata");
  ByteWriter out;
  mcap::append(out, mcap::Metadata{name, metadata});
  output_->write(std::move(out.buffer()), std::nullopt, mcap::MetadataIndex{0, 0, name});
  ++statistics_.metadata_count;
}

McapWriterStats McapWriter::stats() const {
  McapWriterStats s = stats_;
  if (output_) {
    const McapOutputTotals t = output_->totals();
    s.chunks = t.chunks;
    s.uncompressed_bytes = t.uncompressed_bytes;
    s.compressed_bytes = t.compressed_bytes;
    s.file_bytes = t.file_bytes;
  }
  return s;
}

void McapWriter::close() {
  if (!output_) return;
  flush_chunk();
  output_->drain();
  ByteWriter tail;
  mcap::append_data_end(tail, output_->data_crc());
  const auto summary = summary_and_footer(output_->position() + tail.size());
  tail.bytes(summary);
  output_->write_tail(tail.buffer());
  output_->close();
  stats_ = stats();  // the final sizes, kept after the output is gone
  output_.reset();
}

std::vector<uint8_t> McapWriter::summary_and_footer(uint64_t summary_start) {
  ByteWriter summary;
  std::vector<mcap::SummaryOffset> offsets;
  // Records grouped by opcode, each group announced in the summary offset section.
  auto group = [&](mcap::Op op, const auto& records) {
    const size_t start = summary.size();
    for (const auto& r : records) mcap::append(summary, r);
    if (summary.size() > start)
      offsets.push_back({uint8_t(op), summary_start + start, uint64_t(summary.size() - start)});
  };
  statistics_.schema_count = uint16_t(schemas_.size());
  statistics_.channel_count = uint32_t(channels_.size());
  group(mcap::Op::schema, schemas_);
  group(mcap::Op::channel, channels_);
  group(mcap::Op::statistics, std::vector<mcap::Statistics>{statistics_});
  group(mcap::Op::chunk_index, output_->chunk_indexes());
  group(mcap::Op::attachment_index, output_->attachment_indexes());
  group(mcap::Op::metadata_index, output_->metadata_indexes());

  const uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& o : offsets) mcap::append(summary, o);

  // The footer's CRC covers the summary, the summary offsets and the footer up to the CRC itself.
  mcap::append(summary, mcap::Footer{summary_start, summary_offset_start, 0});
  summary.patch_u32(summary.size() - 4, crc32(summary.buffer().data(), summary.size() - 4));
  for (uint8_t b : mcap::kMagic) summary.u8(b);
  return std::move(summary.buffer());
}

}  // namespace lidarloop
