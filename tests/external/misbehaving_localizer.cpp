// A localizer that breaks the exec: protocol on purpose, at a chosen scan, for the tests of how a run
// ends when the program under test misbehaves. Until then it answers every scan with "no estimate".
//   misbehaving_localizer MODE SCAN
// MODE: sleep (sleeps 30 s instead of answering), exit (exits with status 3), garbage (prints a line
// that is not JSON), wrong-scan (answers for the wrong scan), stop-reading (closes stdin and sleeps),
// linger (answers every scan, then ignores the end of its input and sleeps 30 s); slow (takes SCAN
// milliseconds over every answer, for the measured latency in closed loop); bad-lost ("lost": "yes"),
// bad-protection (a negative bound), lost-without-pose ("lost": true and no pose).
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr,
                 "usage: misbehaving_localizer sleep|exit|garbage|wrong-scan|stop-reading|linger|slow|bad-lost|"
                 "bad-protection|lost-without-pose SCAN\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int at = std::atoi(argv[2]);
  lidarloop::McapReader reader(stdin, "stdin");
  lidarloop::McapMessage m;
  int scan = 0;
  while (reader.next(m)) {
    if (m.channel->topic != lidarloop::log_topics::scan) continue;
    if (mode == "slow") usleep(useconds_t(at) * 1000);
    if (scan == at) {
      if (mode == "sleep") sleep(30);
      if (mode == "exit") return 3;
      if (mode == "garbage") std::printf("hello, simulator\n");
      if (mode == "wrong-scan") std::printf("{\"scan\": %d}\n", scan + 1);
      if (mode == "bad-lost") std::printf("{\"scan\": %d, \"x\": 1, \"y\": 2, \"yaw\": 0, \"lost\": \"yes\"}\n", scan);
      if (mode == "bad-protection")
        std::printf("{\"scan\": %d, \"x\": 1, \"y\": 2, \"yaw\": 0, \"protection\": [0.5, -1]}\n", scan);
      if (mode == "lost-without-pose") std::printf("{\"scan\": %d, \"lost\": true}\n", scan);
      if (mode == "stop-reading") {
        std::fclose(stdin);
        sleep(30);
      }
      std::fflush(stdout);
    }
    std::printf("{\"scan\": %d}\n", scan++);
    std::fflush(stdout);
  }
  if (mode == "linger") sleep(30);
  return 0;
}
