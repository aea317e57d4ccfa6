#pragma once
// Runs programs as a pool of child processes: at most N at once, each with its output in its own log
// file and a time limit, and tells how each ended. A child that crashes or hangs ends only itself.
// Each child leads its own process group, so a timeout or an interrupt stops whatever it started too.
#include <functional>
#include <string>
#include <vector>

namespace lidarloop {

struct PoolTask {
  std::vector<std::string> argv;  // argv[0] is the program's path
  std::string log_path;           // stdout and stderr go here
  double timeout_s = 0;           // > 0
};

struct PoolTaskEnd {
  enum class How { exited, signalled, timed_out, not_started } how = How::exited;
  int code = 0;  // the exit code, or the signal
  double wall_s = 0;
  bool interrupted = false;  // stopped because the pool was interrupted: not the run's own doing
};

struct PoolProgress {
  size_t finished = 0, running = 0, total = 0;
  double elapsed_s = 0;
};

// Runs every task, at most `parallel` at a time, in the tasks' order. `on_end` is called (on this
// thread) as each one ends; `on_tick` a few times a second. Returns false when SIGINT or SIGTERM
// arrived: the running children are then stopped and the remaining tasks not started.
bool run_process_pool(const std::vector<PoolTask>& tasks, int parallel,
                      const std::function<void(size_t task, const PoolTaskEnd&)>& on_end,
                      const std::function<void(const PoolProgress&)>& on_tick = {});

// The path of the running executable (to start more of itself).
std::string self_executable();

}  // namespace lidarloop
