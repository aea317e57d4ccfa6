#include "external/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

#include "common/input_error.hpp"

extern char** environ;

namespace lidarloop {
namespace {

constexpr int kPipeBytes = 1 << 20;

// Writing to a program that has gone away raises SIGPIPE, whose default kills us. Blocked on this
// thread while we write (a process-wide SIG_IGN would be hidden global state, and inherited by every
// program started later); EPIPE then reports it, and a pending SIGPIPE is consumed before unblocking.
class SigpipeBlocked {
 public:
  SigpipeBlocked() {
    sigemptyset(&pipe_);
    sigaddset(&pipe_, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_, &old_);
  }
  ~SigpipeBlocked() {
    sigset_t pending;
    sigpending(&pending);
    if (sigismember(&pending, SIGPIPE)) {
      const timespec zero{0, 0};
      sigtimedwait(&pipe_, nullptr, &zero);
    }
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }

 private:
  sigset_t pipe_, old_;
};

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0].empty()) throw InputError("no program to start");
  int in[2], out[2];
  if (::pipe2(in, O_CLOEXEC) != 0) throw InputError(argv[0] + ": cannot create a pipe (" + std::strerror(errno) + ")");
  if (::pipe2(out, O_CLOEXEC) != 0) {
    ::close(in[0]);
    ::close(in[1]);
    throw InputError(argv[0] + ": cannot create a pipe (" + std::strerror(errno) + ")");
  }
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);  // dup2 clears close-on-exec
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigmask(&attr, &none);  // not our blocked SIGPIPE
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  const int failed = posix_spawnp(&pid_, argv[0].c_str(), &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(in[0]);
  ::close(out[1]);
  if (failed != 0) {
    ::close(in[1]);
    ::close(out[0]);
    pid_ = -1;
    throw InputError(argv[0] + ": cannot start the program (" + std::strerror(failed) + ")");
  }
  stdin_fd_ = in[1];
  stdout_fd_ = out[0];
  // Best effort: a scan (about 1.2 MB) then crosses in a few writes instead of twenty 64 KiB ones, each
  // a round trip between the two processes. 1 MiB is Linux's default limit for unprivileged users.
  ::fcntl(stdin_fd_, F_SETPIPE_SZ, kPipeBytes);
  ::fcntl(stdin_fd_, F_SETFL, ::fcntl(stdin_fd_, F_GETFL) | O_NONBLOCK);
  ::fcntl(stdout_fd_, F_SETFL, ::fcntl(stdout_fd_, F_GETFL) | O_NONBLOCK);
}

ChildProcess::~ChildProcess() {
  close_fd(stdin_fd_);
  close_fd(stdout_fd_);
  if (pid_ > 0 && !exit_status_) kill();
}

void ChildProcess::send(std::span<const uint8_t> bytes) {
  if (outgoing_sent_ == outgoing_.size()) {
    outgoing_.clear();
    outgoing_sent_ = 0;
  }
  outgoing_.insert(outgoing_.end(), bytes.begin(), bytes.end());
}

bool ChildProcess::pump(Clock::time_point deadline) {
  const bool want_write = stdin_fd_ >= 0 && !stdin_broken_ && outgoing_sent_ < outgoing_.size();
  const bool want_read = stdout_fd_ >= 0 && !stdout_ended_;
  if (!want_write && !want_read) return false;
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  if (left < 0) return false;
  pollfd fds[2];
  nfds_t n = 0;
  if (want_write) fds[n++] = {stdin_fd_, POLLOUT, 0};
  if (want_read) fds[n++] = {stdout_fd_, POLLIN, 0};
  const int ready = ::poll(fds, n, int(std::min<long long>(left + 1, 1000)));
  if (ready < 0 && errno != EINTR) throw InputError(std::string("poll failed: ") + std::strerror(errno));
  if (ready <= 0) return true;
  for (nfds_t i = 0; i < n; ++i) {
    if (fds[i].fd == stdin_fd_ && (fds[i].revents & (POLLOUT | POLLERR | POLLHUP))) {
      const SigpipeBlocked guard;
      const ssize_t w = ::write(stdin_fd_, outgoing_.data() + outgoing_sent_,
                                std::min<size_t>(outgoing_.size() - outgoing_sent_, 1 << 20));
      if (w > 0) outgoing_sent_ += size_t(w);
      if (w < 0 && errno != EAGAIN && errno != EINTR) stdin_broken_ = true;  // EPIPE: it stopped reading
    }
    if (fds[i].fd == stdout_fd_ && (fds[i].revents & (POLLIN | POLLERR | POLLHUP))) {
      char chunk[1 << 16];
      const ssize_t r = ::read(stdout_fd_, chunk, sizeof chunk);
      if (r > 0) buffer_.append(chunk, size_t(r));
      if (r == 0 || (r < 0 && errno != EAGAIN && errno != EINTR)) stdout_ended_ = true;
    }
  }
  return true;
}

ChildProcess::LineStatus ChildProcess::read_line(Clock::time_point deadline, std::string& line, size_t max_line_bytes) {
  for (;;) {
    if (const size_t end = buffer_.find('\n'); end != std::string::npos) {
      if (end > max_line_bytes) return LineStatus::too_long;
      line.assign(buffer_, 0, end);
      buffer_.erase(0, end + 1);
      return LineStatus::line;
    }
    if (buffer_.size() > max_line_bytes) return LineStatus::too_long;
    if (stdout_ended_) return LineStatus::closed;
    if (stdin_broken_ && outgoing_sent_ < outgoing_.size()) return LineStatus::stdin_closed;
    if (Clock::now() >= deadline || !pump(deadline)) return LineStatus::timed_out;
  }
}

bool ChildProcess::close_stdin(Clock::time_point deadline) {
  while (stdin_fd_ >= 0 && !stdin_broken_ && outgoing_sent_ < outgoing_.size() && Clock::now() < deadline)
    if (!pump(deadline)) break;
  const bool all_sent = outgoing_sent_ == outgoing_.size() && !stdin_broken_;
  close_fd(stdin_fd_);
  return all_sent;
}

std::optional<int> ChildProcess::wait_exit(Clock::time_point deadline) {
  while (!exit_status_) {
    // Drain its stdout meanwhile: a program blocked writing to a full pipe would never exit.
    if (stdout_fd_ >= 0 && !stdout_ended_) pump(std::min(deadline, Clock::now() + std::chrono::milliseconds(5)));
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      exit_status_ = status;
      break;
    }
    if (Clock::now() >= deadline) break;
    if (stdout_fd_ < 0 || stdout_ended_) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return exit_status_;
}

void ChildProcess::kill() {
  if (pid_ <= 0 || exit_status_) return;
  ::kill(-pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  exit_status_ = status;
}

std::string describe_wait_status(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "ended with wait status " + std::to_string(status);
}

}  // namespace lidarloop
