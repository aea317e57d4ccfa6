#pragma once
// What the HD map's layers share on disk: files written whole (never half a file for a reader), files
// read whole with errors naming them, and decimals for people that read back exactly.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/yaml_reader.hpp"

namespace lidarloop {

// Writes to a temporary name (path + ".tmp") and renames it over `path`. InputError naming the file.
void write_file_atomically(const std::filesystem::path& path, const std::string& bytes);
// The file's bytes; InputError "<file>: <what> is missing" or "cannot read".
std::string read_file_bytes(const std::filesystem::path& path, const std::string& what);
// The shortest decimal that reads back to the same double: 0.2 stays "0.2", lat/lon stay exact.
std::string shortest_decimal(double v);

// A layer header's `format: <name>` and `version: <version>`: anything else fails at its line.
void read_format_and_version(const YamlReader& yaml, YamlMap& root, const std::string& name, long version);
// A layer header's `tiles: [[ix, iy], ...]`, sorted; a tile listed twice fails at its line.
std::vector<std::pair<int, int>> read_tile_list(const YamlReader& yaml, const YAML::Node& tiles);
// "(ix, iy)", for messages.
std::string tile_name(int tx, int ty);
// Floor division: C++ '/' truncates towards zero, which would fold tiles -1 and 0 together.
int64_t floor_div(int64_t a, int64_t b);

}  // namespace lidarloop
