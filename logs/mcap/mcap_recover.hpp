#pragma once
// `lidarloop recover`: rebuilds a valid MCAP file from a damaged one, typically a log whose writer
// was killed (no summary, a half-written last chunk) or a file cut or corrupted in transit.
//
// Every record that is intact is kept: schemas, channels, attachments, metadata, and every message of
// every chunk that decompresses and passes its CRC. A chunk that fails is skipped; when the framing
// itself is broken (a length running past the end, an impossible opcode) the scan resynchronises on
// the next record that parses as a whole, CRC-checked chunk, so damage in the middle of a file loses
// only the chunks it touches. The output is written by McapWriter: chunked, indexed, summarised.
#include <cstdint>
#include <string>
#include <vector>

#include "logs/mcap/mcap_writer.hpp"

namespace lidarloop {

struct McapRecoverReport {
  uint64_t input_bytes = 0;
  uint64_t chunks = 0, messages = 0, attachments = 0, metadata = 0;  // kept
  uint64_t skipped_chunks = 0;                                       // framed correctly but corrupt
  uint64_t skipped_bytes = 0;         // passed over while resynchronising, including a cut-off tail
  uint64_t orphan_messages = 0;       // on channels whose definition was lost
  bool complete = false;              // the input reached its Data End record: nothing was missing
  std::vector<std::string> problems;  // the first few, in file order
};

// InputError only when `broken` cannot be read at all or is not an MCAP file, or `fixed` cannot be
// written; damage inside the file is reported, not thrown.
McapRecoverReport recover_mcap(const std::string& broken, const std::string& fixed, McapWriterOptions options = {});

}  // namespace lidarloop
