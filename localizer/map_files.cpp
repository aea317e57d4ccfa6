#include "localizer/map_files.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <fstream>
#include <set>

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

void read_format_and_version(const YamlReader& yaml, YamlMap& root, const std::string& name, long version) {
  const YAML::Node format = root.required("format");
  if (yaml.string(format, "format") != name)
    yaml.fail(format, "format is '" + format.Scalar() + "', expected '" + name + "'");
  const YAML::Node v = root.required("version");
  const long found = yaml.integer_in(v, "version", LONG_MIN, LONG_MAX);
  if (found != version)
    yaml.fail(v, "unsupported version " + std::to_string(found) + " (expected " + std::to_string(version) + ")");
}

std::vector<std::pair<int, int>> read_tile_list(const YamlReader& yaml, const YAML::Node& tiles) {
  yaml.expect_sequence(tiles, "tiles");
  std::vector<std::pair<int, int>> out;
  std::set<std::pair<int, int>> seen;
  for (const YAML::Node& t : tiles) {
    if (!t.IsSequence() || t.size() != 2) yaml.fail(t, "a tile must be [ix, iy]");
    const std::pair<int, int> key{int(yaml.integer_in(t[0], "tile ix", INT_MIN, INT_MAX)),
                                  int(yaml.integer_in(t[1], "tile iy", INT_MIN, INT_MAX))};
    if (!seen.insert(key).second) yaml.fail(t, "tile " + tile_name(key.first, key.second) + " is listed twice");
    out.push_back(key);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string tile_name(int tx, int ty) {
  std::string name = "(";
  name.append(std::to_string(tx)).append(", ").append(std::to_string(ty)).append(")");
  return name;
}

int64_t floor_div(int64_t a, int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

}  // namespace lidarloop
