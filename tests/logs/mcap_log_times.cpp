// Test helper: prints the log time (ns) and topic of every message of an MCAP log, one a line, in file
// order (which is the order the messages were written), for scripts that compare a recovered log with
// a complete one (tests/cli/kill_recording.sh).
#include <cinttypes>
#include <cstdio>
#include <exception>

#include "logs/mcap/mcap_reader.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mcap_log_times FILE.mcap\n");
    return 2;
  }
  try {
    lidarloop::McapReader reader(argv[1]);
    for (lidarloop::McapMessage m; reader.next(m);)
      std::printf("%" PRIu64 " %s\n", m.log_time, m.channel->topic.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mcap_log_times: %s\n", e.what());
    return 2;
  }
  return 0;
}
