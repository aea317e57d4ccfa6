#pragma once
// An exclusive lock on a file, held by this process until the lock is destroyed: how processes that
// share a map cache (one machine, or a shared volume) agree that one of them builds a map while the
// others wait.
//
// flock(2). The kernel drops the lock when the process ends however it ends (exit, crash, kill -9),
// so a crashed builder never leaves the cache stuck. The lock file itself is never deleted: deleting
// it while another process waits on its descriptor would let a third process lock a new file of the
// same name, and two builders would run at once.
//
// Assumption on shared volumes: Linux's NFS client (NFSv4, and NFSv3 with the NLM lock manager) turns
// flock into a whole-file POSIX lock that the server arbitrates, so it holds across machines; an NFS
// volume mounted with `nolock` (or `local_lock=flock`) only locks within one machine. The lock of a
// client that dies is released when its NFSv4 lease expires (about 90 s by default), not at once.
// Within one process, two FileLocks on the same file exclude each other locally; over NFS they may not
// (POSIX locks belong to the process), so one process must not build the same map on two threads.
#include <functional>
#include <string>

namespace lidarloop {

class FileLock {
 public:
  // Creates `path` if needed and locks it, blocking while another process holds it; `on_wait` runs
  // once before blocking, only if the lock is taken. Throws InputError naming the file if it cannot be
  // created or locked.
  explicit FileLock(const std::string& path, const std::function<void()>& on_wait = {});
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace lidarloop
