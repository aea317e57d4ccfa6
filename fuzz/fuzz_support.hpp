#pragma once
// What the fuzz targets share. Each target feeds libFuzzer's bytes to one reader of outside files and
// accepts exactly one outcome besides success: an InputError (the reader's "this file is bad, here is
// why"). Any other exception escapes, and libFuzzer reports it like a crash: the CLI would print
// "internal error" and exit 3 on it, which is a defect. Sanitizer reports, timeouts and running out of
// memory are failures too (fuzz/run_fuzzer.cmake).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

namespace lidarloop::fuzz {

inline std::string_view as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A scratch folder of this process's own, for readers that take a path: created at the first input,
// reused by the next ones (libFuzzer runs inputs one after another in one process), removed at exit.
inline const std::filesystem::path& scratch_dir() {
  struct Scratch {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("lidarloop-fuzz-" + std::to_string(::getpid()));
    Scratch() { std::filesystem::create_directories(path); }
    ~Scratch() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Scratch scratch;
  return scratch.path;
}

inline void write_bytes(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace lidarloop::fuzz
