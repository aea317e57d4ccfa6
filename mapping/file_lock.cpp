#include "mapping/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {

constexpr mode_t kLockFileMode = 0666;  // others sharing the cache must be able to lock it too (umask applies)

// flock, retried when a signal interrupts the wait.
int flock_retrying(int fd, int operation) {
  int r;
  do r = ::flock(fd, operation);
  while (r != 0 && errno == EINTR);
  return r;
}

}  // namespace

FileLock::FileLock(const std::string& path, const std::function<void()>& on_wait) : path_(path) {
  do fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, kLockFileMode);
  while (fd_ < 0 && errno == EINTR);
  if (fd_ < 0) throw InputError(path + ": cannot open lock file: " + std::strerror(errno));
  if (flock_retrying(fd_, LOCK_EX | LOCK_NB) == 0) return;
  if (errno == EWOULDBLOCK) {
    if (on_wait) on_wait();
    if (flock_retrying(fd_, LOCK_EX) == 0) return;
  }
  const int error = errno;
  ::close(fd_);
  throw InputError(path + ": cannot lock file: " + std::strerror(error));
}

FileLock::~FileLock() {
  // Closing the descriptor releases the lock; the file stays for the next process.
  ::close(fd_);
}

}  // namespace lidarloop
