#pragma once
// What the HD map's layers share on disk: files written whole (never half a file for a reader), files
// read whole with errors naming them, and decimals for people that read back exactly.
#include <filesystem>
#include <string>

namespace lidarloop {

// Writes to a temporary name (path + ".tmp") and renames it over `path`. InputError naming the file.
void write_file_atomically(const std::filesystem::path& path, const std::string& bytes);
// The file's bytes; InputError "<file>: <what> is missing" or "cannot read".
std::string read_file_bytes(const std::filesystem::path& path, const std::string& what);
// The shortest decimal that reads back to the same double: 0.2 stays "0.2", lat/lon stay exact.
std::string shortest_decimal(double v);

}  // namespace lidarloop
