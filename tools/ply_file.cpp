#include "tools/ply_file.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "common/input_error.hpp"

namespace lidarloop {

namespace {
constexpr size_t kRecordSize = 3 * 4 + 1 + 2 + 4;

const char* kProperties =
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar intensity\n"
    "property ushort ring\n"
    "property float time\n";
}  // namespace

void write_ply(const std::string& path, const PointCloud& cloud) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot write file");
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment lidarloop HDL-32E scan, sensor frame (x forward, y left, z up), metres\n"
      << "comment stamp_ns " << cloud.stamp_ns << "\n"
      << "element vertex " << cloud.points.size() << "\n"
      << kProperties << "end_header\n";
  std::string buffer(cloud.points.size() * kRecordSize, '\0');
  char* p = buffer.data();
  for (const auto& pt : cloud.points) {
    const float time = float(double(pt.t_ns) * 1e-9);
    std::memcpy(p, &pt.x, 4), std::memcpy(p + 4, &pt.y, 4), std::memcpy(p + 8, &pt.z, 4);
    std::memcpy(p + 12, &pt.intensity, 1), std::memcpy(p + 13, &pt.ring, 2), std::memcpy(p + 15, &time, 4);
    p += kRecordSize;
  }
  out.write(buffer.data(), std::streamsize(buffer.size()));
  out.close();
  if (!out) throw InputError(path + ": write failed");
}

PointCloud read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  std::string line, properties;
  size_t count = 0;
  PointCloud cloud;
  bool binary = false, header_done = false;
  while (std::getline(in, line)) {
    if (line == "end_header") {
      header_done = true;
      break;
    }
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    if (tag == "format")
      binary = line == "format binary_little_endian 1.0";
    else if (tag == "element")
      words >> tag >> count;
    else if (tag == "property")
      properties += line + "\n";
    else if (tag == "comment" && line.rfind("comment stamp_ns ", 0) == 0)
      cloud.stamp_ns = std::stoll(line.substr(17));
  }
  if (!header_done || !binary || properties != kProperties)
    throw InputError(path + ": not a lidarloop scan PLY (unexpected header)");
  std::string buffer(count * kRecordSize, '\0');
  if (!in.read(buffer.data(), std::streamsize(buffer.size())))
    throw InputError(path + ": truncated (header promises " + std::to_string(count) + " points)");
  cloud.points.resize(count);
  const char* p = buffer.data();
  for (auto& pt : cloud.points) {
    float time = 0;
    std::memcpy(&pt.x, p, 4), std::memcpy(&pt.y, p + 4, 4), std::memcpy(&pt.z, p + 8, 4);
    std::memcpy(&pt.intensity, p + 12, 1), std::memcpy(&pt.ring, p + 13, 2), std::memcpy(&time, p + 15, 4);
    pt.t_ns = uint32_t(std::llround(double(time) * 1e9));
    p += kRecordSize;
  }
  return cloud;
}

}  // namespace lidarloop
