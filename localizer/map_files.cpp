#include "localizer/map_files.hpp"

#include <array>
#include <charconv>
#include <fstream>

#include "common/input_error.hpp"

namespace lidarloop {

namespace fs = std::filesystem;

void write_file_atomically(const fs::path& path, const std::string& bytes) {
  const fs::path temp = path.string() + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) throw InputError(temp.string() + ": cannot write file");
  }
  std::error_code ec;
  fs::rename(temp, path, ec);
  if (ec) throw InputError(path.string() + ": cannot write file: " + ec.message());
}

std::string read_file_bytes(const fs::path& path, const std::string& what) {
  const std::string file = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(file + ": " + what + " is missing");
  std::string bytes;
  std::ifstream in(path, std::ios::binary);
  if (!in.is_open()) throw InputError(file + ": cannot open " + what);
  bytes.resize(size_t(fs::file_size(path, ec)));
  if (ec || !in.read(bytes.data(), std::streamsize(bytes.size()))) throw InputError(file + ": cannot read " + what);
  return bytes;
}

std::string shortest_decimal(double v) {
  std::array<char, 64> buf{};
  const auto result = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), result.ptr);
}

}  // namespace lidarloop
