#include "sweep/process_pool.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <map>
#include <thread>

#include "common/input_error.hpp"

namespace lidarloop {
namespace {

using Clock = std::chrono::steady_clock;

constexpr auto kPoll = std::chrono::milliseconds(20);      // how soon a finished child is replaced
constexpr auto kTick = std::chrono::milliseconds(500);     // progress updates
constexpr auto kGraceAfterTerm = std::chrono::seconds(5);  // an interrupted child's time to write its files
constexpr int kExecFailed = 127;                           // the shell's code for "command not found"

// A signal handler can only set a flag; this is the one piece of process-wide state, as the signal is.
volatile std::sig_atomic_t g_stop_signal = 0;
void on_stop_signal(int signal) { g_stop_signal = signal; }

struct Running {
  size_t task;
  Clock::time_point start;
  bool timed_out = false;
};

pid_t start(const PoolTask& task) {
  std::vector<char*> argv;
  for (const auto& a : task.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const int log = ::open(task.log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) throw InputError(task.log_path + ": cannot create the run's log");
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log);
    throw InputError("cannot start a process: fork failed");
  }
  if (pid == 0) {     // the child: only async-signal-safe calls until exec
    ::setpgid(0, 0);  // exec resets the parent's SIGINT/SIGTERM handlers to the default
    ::dup2(log, STDOUT_FILENO), ::dup2(log, STDERR_FILENO);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, STDIN_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(kExecFailed);
  }
  ::setpgid(pid, pid);  // also here: whichever runs first, the group exists before a kill
  ::close(log);
  return pid;
}

}  // namespace

std::string self_executable() {
  char path[4096];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) throw InputError("cannot find the lidarloop executable (/proc/self/exe)");
  return std::string(path, size_t(n));
}

bool run_process_pool(const std::vector<PoolTask>& tasks, int parallel,
                      const std::function<void(size_t, const PoolTaskEnd&)>& on_end,
                      const std::function<void(const PoolProgress&)>& on_tick) {
  g_stop_signal = 0;
  struct sigaction action {
  }, old_int{}, old_term{};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, &old_int);
  ::sigaction(SIGTERM, &action, &old_term);

  const Clock::time_point t0 = Clock::now();
  Clock::time_point last_tick = t0;
  std::map<pid_t, Running> running;
  size_t next = 0, finished = 0;
  Clock::time_point stop_sent{};
  while (next < tasks.size() || !running.empty()) {
    while (!g_stop_signal && next < tasks.size() && int(running.size()) < std::max(1, parallel)) {
      running[start(tasks[next])] = {next, Clock::now()};
      ++next;
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      const auto it = running.find(pid);
      if (it == running.end()) continue;
      PoolTaskEnd end;
      end.wall_s = std::chrono::duration<double>(Clock::now() - it->second.start).count();
      if (it->second.timed_out) {
        end.how = PoolTaskEnd::How::timed_out;
      } else if (WIFSIGNALED(status)) {
        end.how = PoolTaskEnd::How::signalled, end.code = WTERMSIG(status);
      } else {
        end.code = WEXITSTATUS(status);
        end.how = end.code == kExecFailed ? PoolTaskEnd::How::not_started : PoolTaskEnd::How::exited;
      }
      end.interrupted = g_stop_signal != 0;
      const size_t task = it->second.task;
      ::kill(-pid, SIGKILL);  // anything the run left behind in its group
      running.erase(it);
      ++finished;
      on_end(task, end);
      continue;
    }
    const Clock::time_point now = Clock::now();
    for (auto& [child, r] : running)
      if (!r.timed_out && std::chrono::duration<double>(now - r.start).count() > tasks[r.task].timeout_s) {
        r.timed_out = true;
        ::kill(-child, SIGKILL);
      }
    if (g_stop_signal) {
      if (stop_sent == Clock::time_point{}) {
        stop_sent = now;
        for (const auto& [child, r] : running) ::kill(-child, SIGTERM);
      } else if (now - stop_sent > kGraceAfterTerm) {
        for (const auto& [child, r] : running) ::kill(-child, SIGKILL);
      }
    }
    if (on_tick && now - last_tick >= kTick) {
      last_tick = now;
      on_tick({finished, running.size(), tasks.size(), std::chrono::duration<double>(now - t0).count()});
    }
    std::this_thread::sleep_for(kPoll);
  }
  ::sigaction(SIGINT, &old_int, nullptr);
  ::sigaction(SIGTERM, &old_term, nullptr);
  return g_stop_signal == 0;
}

}  // namespace lidarloop
