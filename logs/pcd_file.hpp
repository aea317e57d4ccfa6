#pragma once
// The header of a binary PCD v0.7 file (the Point Cloud Library's format, "The PCD (Point Cloud Data)
// file format" in PCL's documentation): one line per key, then `DATA binary` and the points packed
// field after field, little-endian. Every PCD this project writes (a log's scans, Autoware's point
// cloud map) starts with it, so the layout lives here once.
#include <cstddef>
#include <string>
#include <vector>

namespace lidarloop {

struct PcdField {
  std::string name;
  int size = 4;     // bytes
  char type = 'F';  // F float, U unsigned, I signed
};

// An unorganised cloud (HEIGHT 1) of `points` points; `comment` goes on the first line after "# .PCD v0.7 - ".
std::string binary_pcd_header(const std::vector<PcdField>& fields, size_t points, const std::string& comment);

}  // namespace lidarloop
