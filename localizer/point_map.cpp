#include "localizer/point_map.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "common/crc32.hpp"
#include "common/input_error.hpp"
#include "common/little_endian.hpp"
#include "common/yaml_reader.hpp"
#include "localizer/map_files.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHeaderFile = "points.yaml";
constexpr const char* kTilesDir = "points";
constexpr const char* kTileExtension = ".pts";
constexpr const char* kFormatName = "lidarloop-point-map";
constexpr long kFormatVersion = 1;
constexpr std::array<char, 4> kTileMagic = {'L', 'L', 'P', 'C'};
constexpr uint32_t kTileVersion = 1;
constexpr size_t kWordBytes = 4;
constexpr size_t kTileHeaderBytes = 5 * kWordBytes;  // magic, version, tile_x, tile_y, count
constexpr size_t kPointBytes = 3 * kWordBytes;
constexpr double kMinVoxel = 0.01, kMaxVoxel = 10.0;
constexpr long kMaxTileVoxels = 100000;

// A global voxel index packed into 64 bits: 21 bits per axis, offset to be non-negative (+-1 048 576
// voxels: +-419 km at 0.4 m, far beyond any map's local frame). Its order is x, then y, then z.
constexpr int kAxisBits = 21;
constexpr int64_t kAxisOffset = int64_t(1) << (kAxisBits - 1);
constexpr uint64_t kAxisMask = (uint64_t(1) << kAxisBits) - 1;

uint64_t pack(int64_t ix, int64_t iy, int64_t iz) {
  return (uint64_t(ix + kAxisOffset) << (2 * kAxisBits)) | (uint64_t(iy + kAxisOffset) << kAxisBits) |
         uint64_t(iz + kAxisOffset);
}
std::array<int64_t, 3> unpack(uint64_t key) {
  return {int64_t((key >> (2 * kAxisBits)) & kAxisMask) - kAxisOffset,
          int64_t((key >> kAxisBits) & kAxisMask) - kAxisOffset, int64_t(key & kAxisMask) - kAxisOffset};
}
bool in_range(int64_t i) { return i >= -kAxisOffset && i < kAxisOffset; }

std::string tile_name(const std::pair<int, int>& key) { return lidarloop::tile_name(key.first, key.second); }

void check_header(const PointMapHeader& h, const char* who) {
  if (!(h.voxel_m >= kMinVoxel && h.voxel_m <= kMaxVoxel))
    throw std::invalid_argument(std::string(who) + ": voxel_m must be in [0.01, 10] m");
  if (h.tile_voxels < 1 || h.tile_voxels > kMaxTileVoxels)
    throw std::invalid_argument(std::string(who) + ": tile_voxels out of range");
}

std::string header_yaml(const PointMapHeader& h) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kFormatName;
  out << YAML::Key << "version" << YAML::Value << kFormatVersion;
  out << YAML::Key << "world" << YAML::Value << h.world;
  out << YAML::Key << "world_hash" << YAML::Value << h.world_hash;
  out << YAML::Key << "voxel_m" << YAML::Value << shortest_decimal(h.voxel_m);
  out << YAML::Key << "tile_voxels" << YAML::Value << h.tile_voxels;
  out << YAML::Key << "tiles" << YAML::Value << YAML::BeginSeq;
  for (const auto& [tx, ty] : h.tiles) out << YAML::Flow << YAML::BeginSeq << tx << ty << YAML::EndSeq;
  out << YAML::EndSeq << YAML::EndMap;
  if (!out.good()) throw std::logic_error("point map header: YAML emitter error: " + out.GetLastError());
  return std::string(out.c_str()) + "\n";
}

std::string encode_tile(const std::pair<int, int>& key, const std::vector<Eigen::Vector3f>& points) {
  std::string out;
  out.reserve(kTileHeaderBytes + points.size() * kPointBytes + kWordBytes);
  out.append(kTileMagic.data(), kTileMagic.size());
  append_le(out, kTileVersion, kWordBytes);
  append_le(out, uint32_t(key.first), kWordBytes);
  append_le(out, uint32_t(key.second), kWordBytes);
  append_le(out, uint32_t(points.size()), kWordBytes);
  for (const Eigen::Vector3f& p : points)
    for (int k = 0; k < 3; ++k) append_le(out, std::bit_cast<uint32_t>(p[k]), kWordBytes);
  append_le(out, crc32(out.data(), out.size()), kWordBytes);
  return out;
}

uint32_t word(const std::string& bytes, size_t at) { return uint32_t(get_le(bytes.data() + at, kWordBytes)); }

}  // namespace

PointMapBuilder::PointMapBuilder(PointMapHeader header) : header_(std::move(header)) {
  check_header(header_, "PointMapBuilder");
  header_.tiles.clear();
}

PointMapBuilder::Tile& PointMapBuilder::open_tile(const std::pair<int, int>& key) {
  if (taken_.count(key))
    throw std::logic_error("PointMapBuilder: a point falls in tile " + tile_name(key) +
                           ", which was already handed over as finished");
  auto [it, inserted] = tiles_.try_emplace(key);
  if (inserted) header_.tiles.insert(std::lower_bound(header_.tiles.begin(), header_.tiles.end(), key), key);
  return it->second;
}

void PointMapBuilder::add(const Eigen::Vector3d& p) {
  if (!p.allFinite()) return;
  const double v = header_.voxel_m;
  const double fx = std::floor(p.x() / v), fy = std::floor(p.y() / v), fz = std::floor(p.z() / v);
  if (!in_range(int64_t(fx)) || !in_range(int64_t(fy)) || !in_range(int64_t(fz))) return;  // no map reaches it
  const int64_t ix = int64_t(fx), iy = int64_t(fy), iz = int64_t(fz);
  const uint64_t index = pack(ix, iy, iz);
  if (last_sum_ == nullptr || index != last_index_) {
    const std::pair<int, int> tile{int(floor_div(ix, header_.tile_voxels)), int(floor_div(iy, header_.tile_voxels))};
    last_sum_ = &open_tile(tile)[index];
    last_index_ = index;
  }
  Sum& s = *last_sum_;
  s.x += float(p.x() - fx * v), s.y += float(p.y() - fy * v), s.z += float(p.z() - fz * v);
  ++s.count;
}

void PointMapBuilder::merge(const PointMapBuilder& other) {
  if (other.header_.voxel_m != header_.voxel_m || other.header_.tile_voxels != header_.tile_voxels)
    throw std::invalid_argument("PointMapBuilder::merge: maps differ in voxel size or tiling");
  for (const auto& [key, voxels] : other.tiles_) {
    Tile& mine = open_tile(key);
    for (const auto& [index, sum] : voxels) {
      Sum& s = mine[index];
      s.x += sum.x, s.y += sum.y, s.z += sum.z, s.count += sum.count;
    }
  }
}

std::vector<Eigen::Vector3f> PointMapBuilder::take_tile(const std::pair<int, int>& key) {
  last_sum_ = nullptr;  // it may be in this tile
  taken_.insert(key);
  const auto it = tiles_.find(key);
  if (it == tiles_.end()) return {};
  std::vector<std::pair<uint64_t, Sum>> voxels(it->second.begin(), it->second.end());
  tiles_.erase(it);
  std::sort(voxels.begin(), voxels.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3f> points;
  points.reserve(voxels.size());
  const double v = header_.voxel_m;
  for (const auto& [index, s] : voxels) {
    const auto [ix, iy, iz] = unpack(index);
    const double n = s.count;
    points.emplace_back(float(double(ix) * v + s.x / n), float(double(iy) * v + s.y / n),
                        float(double(iz) * v + s.z / n));
  }
  return points;
}

size_t PointMapBuilder::voxel_count() const {
  size_t n = 0;
  for (const auto& [key, voxels] : tiles_) n += voxels.size();
  return n;
}

PointMapWriter::PointMapWriter(const std::string& dir) : dir_(dir) {
  const fs::path tiles = fs::path(dir) / kTilesDir;
  std::error_code ec;
  fs::remove(fs::path(dir) / kHeaderFile, ec);  // a half-replaced layer fails loudly
  fs::remove_all(tiles, ec);
  fs::create_directories(tiles, ec);
  if (ec) throw InputError(tiles.string() + ": cannot create the point map folder: " + ec.message());
}

void PointMapWriter::write_tile(const std::pair<int, int>& key, const std::vector<Eigen::Vector3f>& points) {
  if (points.empty()) return;  // no points, no tile
  write_file_atomically(point_tile_file(dir_, key), encode_tile(key, points));
  written_.insert(key);
}

void PointMapWriter::finish(const PointMapHeader& header) {
  PointMapHeader written = header;
  written.tiles.assign(written_.begin(), written_.end());  // sorted
  for (const auto& key : written.tiles)
    if (!std::binary_search(header.tiles.begin(), header.tiles.end(), key))
      throw std::logic_error("PointMapWriter::finish: tile " + tile_name(key) + " was written but is not the map's");
  write_file_atomically(fs::path(dir_) / kHeaderFile, header_yaml(written));
}

std::string point_tile_file(const std::string& dir, const std::pair<int, int>& key) {
  std::string name = std::to_string(key.first);
  name.append("_").append(std::to_string(key.second)).append(kTileExtension);
  return (fs::path(dir) / kTilesDir / name).string();
}

bool has_point_map(const std::string& dir) {
  std::error_code ec;
  return fs::exists(fs::path(dir) / kHeaderFile, ec);
}

PointMapHeader read_point_map_header(const std::string& dir) {
  const YamlReader yaml = YamlReader::open((fs::path(dir) / kHeaderFile).string());
  YamlMap root(yaml, yaml.root(), "point map header");
  PointMapHeader h;
  read_format_and_version(yaml, root, kFormatName, kFormatVersion);
  h.world = yaml.string(root.required("world"), "world");
  h.world_hash = yaml.string(root.required("world_hash"), "world_hash");
  h.voxel_m = yaml.number_in(root.required("voxel_m"), "voxel_m", kMinVoxel, kMaxVoxel);
  h.tile_voxels = int(yaml.integer_in(root.required("tile_voxels"), "tile_voxels", 1, kMaxTileVoxels));
  const YAML::Node tiles = root.required("tiles");
  root.done();
  h.tiles = read_tile_list(yaml, tiles);
  return h;
}

std::vector<Eigen::Vector3f> read_point_tile(const std::string& file, const std::pair<int, int>& key) {
  const std::string bytes = read_file_bytes(file, "point map tile");
  if (bytes.size() < kTileHeaderBytes + kWordBytes)
    throw InputError(file + ": truncated point map tile (" + std::to_string(bytes.size()) + " bytes)");
  if (!std::equal(kTileMagic.begin(), kTileMagic.end(), bytes.begin()))
    throw InputError(file + ": not a point map tile (bad magic, expected 'LLPC')");
  if (const uint32_t version = word(bytes, 4); version != kTileVersion)
    throw InputError(file + ": unsupported point tile version " + std::to_string(version) + " (expected " +
                     std::to_string(kTileVersion) + ")");
  const uint64_t count = word(bytes, 16);
  const uint64_t expected = kTileHeaderBytes + count * kPointBytes + kWordBytes;
  if (bytes.size() != expected)
    throw InputError(file + ": truncated or overlong point map tile (" + std::to_string(bytes.size()) + " bytes, its " +
                     std::to_string(count) + " points need " + std::to_string(expected) + ")");
  const uint32_t stored = word(bytes, expected - kWordBytes), computed = crc32(bytes.data(), expected - kWordBytes);
  if (stored != computed) {
    std::ostringstream msg;
    msg << file << ": checksum mismatch (CRC-32 stored 0x" << std::hex << stored << ", computed 0x" << computed
        << "): the point map tile is corrupt";
    throw InputError(msg.str());
  }
  const std::pair<int, int> in_file{int32_t(word(bytes, 8)), int32_t(word(bytes, 12))};
  if (in_file != key)
    throw InputError(file + ": file holds tile " + tile_name(in_file) + " but its name says " + tile_name(key));
  std::vector<Eigen::Vector3f> points(count);
  for (size_t i = 0, at = kTileHeaderBytes; i < count; ++i)
    for (int k = 0; k < 3; ++k, at += kWordBytes) points[i][k] = std::bit_cast<float>(word(bytes, at));
  for (const Eigen::Vector3f& p : points)
    if (!p.allFinite()) throw InputError(file + ": a point is not finite");
  return points;
}

PointMap::PointMap(const std::string& dir, size_t max_cached_tiles)
    : dir_(dir), header_(read_point_map_header(dir)), max_cached_(std::max<size_t>(max_cached_tiles, 1)) {
  present_.insert(header_.tiles.begin(), header_.tiles.end());
}

const std::vector<Eigen::Vector3f>& PointMap::tile(const std::pair<int, int>& key) {
  if (const auto hit = cache_.find(key); hit != cache_.end()) {
    lru_.remove(key);
    lru_.push_front(key);
    return hit->second;
  }
  std::vector<Eigen::Vector3f> points = read_point_tile(point_tile_file(dir_, key), key);  // before the cache changes
  ++loads_;
  if (cache_.size() >= max_cached_) {
    cache_.erase(lru_.back());
    lru_.pop_back();
  }
  lru_.push_front(key);
  return cache_.emplace(key, std::move(points)).first->second;
}

std::vector<Eigen::Vector3d> PointMap::points_near(const Eigen::Vector2d& centre, double radius) {
  std::vector<Eigen::Vector3d> out;
  if (!centre.allFinite() || !(radius >= 0)) return out;
  const double size = header_.tile_size_m();
  const int tx0 = int(std::floor((centre.x() - radius) / size)), tx1 = int(std::floor((centre.x() + radius) / size));
  const int ty0 = int(std::floor((centre.y() - radius) / size)), ty1 = int(std::floor((centre.y() + radius) / size));
  const double r2 = radius * radius;
  for (int tx = tx0; tx <= tx1; ++tx)
    for (int ty = ty0; ty <= ty1; ++ty) {
      if (!present_.count({tx, ty})) continue;
      for (const Eigen::Vector3f& p : tile({tx, ty})) {
        const Eigen::Vector3d q = p.cast<double>();
        if ((q.head<2>() - centre).squaredNorm() <= r2) out.push_back(q);
      }
    }
  return out;
}

}  // namespace lidarloop
