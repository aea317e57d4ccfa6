#pragma once
#include <stdexcept>

namespace lidarloop {

// Bad input from a user's file or command line. The message names the file (and where in it) and
// what is wrong; the CLI prints it and exits with code 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace lidarloop
