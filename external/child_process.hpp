#pragma once
// Another program as a child process we talk to over pipes: bytes to its stdin, lines from its stdout,
// each wait bounded by a deadline, so a program that hangs, stops reading or dies cannot hang us.
// Its stderr is ours (what it prints for people reaches the terminal or the run's log). It leads its
// own process group, so stopping it also stops whatever it started (a shell, node's helpers).
#include <sys/types.h>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace lidarloop {

class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;

  // Starts argv[0] (searched in PATH when it has no slash). InputError if it cannot be started.
  explicit ChildProcess(const std::vector<std::string>& argv);
  // Kills the process group if the program still runs, and reaps it.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Queues bytes for its stdin; they go out while read_line() waits.
  void send(std::span<const uint8_t> bytes);

  enum class LineStatus {
    line,          // `line` holds the next line, without its '\n'
    timed_out,     // the deadline passed first
    closed,        // its stdout ended (it exited or closed it) before a whole line
    stdin_closed,  // it stopped reading with bytes still queued (closed stdin or exited)
    too_long,      // a line longer than max_line_bytes: not a sane answer
  };
  // Sends what is queued and reads until a whole line has arrived, or until `deadline`.
  LineStatus read_line(Clock::time_point deadline, std::string& line, size_t max_line_bytes = 1 << 16);

  // Sends what is queued (until `deadline`), then closes its stdin: end of input. False if the bytes
  // could not all be sent.
  bool close_stdin(Clock::time_point deadline);
  // Waits for the program to exit until `deadline`; its wait status, or nothing if it still runs.
  std::optional<int> wait_exit(Clock::time_point deadline);
  // SIGKILL to its process group, then reaps it.
  void kill();

  // What stdout held after the last line read (unread output), for error messages.
  const std::string& unread_output() const { return buffer_; }
  pid_t pid() const { return pid_; }

 private:
  // One poll round: writes what it can, reads what there is. False when nothing can progress any more
  // (the deadline passed).
  bool pump(Clock::time_point deadline);

  pid_t pid_ = -1;
  int stdin_fd_ = -1, stdout_fd_ = -1;
  bool stdout_ended_ = false, stdin_broken_ = false;
  std::optional<int> exit_status_;
  std::vector<uint8_t> outgoing_;
  size_t outgoing_sent_ = 0;
  std::string buffer_;  // stdout read but not yet handed out as lines
};

// "exited with status 3", "killed by signal 11 (Segmentation fault)".
std::string describe_wait_status(int status);

}  // namespace lidarloop
