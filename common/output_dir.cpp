#include "common/output_dir.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "common/input_error.hpp"

namespace lidarloop {

void prepare_output_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
  // access() sees a read-only file system and missing permissions (though not, for root, a mode).
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(dir + ": cannot write into the output folder (" + std::strerror(errno) + ")");
}

}  // namespace lidarloop
