#include "localizer/intensity_map.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
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

// map.yaml
constexpr const char* kHeaderFile = "map.yaml";
constexpr const char* kTilesDir = "tiles";
constexpr const char* kFormatName = "lidarloop-intensity-map";
constexpr const char* kProjection = "transverse_mercator";
constexpr long kFormatVersion = 1;
constexpr long kMinTileCells = 8;
constexpr long kMaxTileCells = 4096;
constexpr double kMaxLatitudeDeg = 90;
constexpr double kMaxLongitudeDeg = 180;
// tile_size_m is redundant (resolution_m * tile_cells); it is written for people, and checked on reading
// only up to the rounding of the printed decimal.
constexpr double kTileSizeRelativeTolerance = 1e-9;

// Tile files: little-endian; header, cells, CRC-32 of everything before it.
constexpr std::array<char, 4> kTileMagic = {'L', 'L', 'I', 'T'};
constexpr uint32_t kTileVersion = 1;
constexpr size_t kWordBytes = 4;                     // every field is a 32-bit word
constexpr size_t kTileHeaderBytes = 5 * kWordBytes;  // magic, version, tile_x, tile_y, tile_cells
constexpr size_t kCellBytes = 3 * kWordBytes;        // count, mean, m2
constexpr size_t kCrcBytes = kWordBytes;
constexpr const char* kTileExtension = ".tile";
constexpr const char* kTempSuffix = ".tmp";

// Points exactly on a cell boundary (x = k * resolution, e.g. 0.6 at 0.2 m) must land in the cell that
// starts there although x / resolution may round to just below k; a few ulps decide, far below any
// physical distance.
constexpr double kBoundarySnapUlps = 64;

void put_u32(std::string& out, uint32_t v) { append_le(out, v, sizeof v); }
void put_i32(std::string& out, int32_t v) { put_u32(out, static_cast<uint32_t>(v)); }
void put_f32(std::string& out, float v) { put_u32(out, std::bit_cast<uint32_t>(v)); }

uint32_t get_u32(const std::string& in, size_t offset) {
  return uint32_t(get_le(in.data() + offset, sizeof(uint32_t)));
}
int32_t get_i32(const std::string& in, size_t offset) { return static_cast<int32_t>(get_u32(in, offset)); }
float get_f32(const std::string& in, size_t offset) { return std::bit_cast<float>(get_u32(in, offset)); }

size_t tile_file_bytes(size_t tile_cells) {
  return kTileHeaderBytes + tile_cells * tile_cells * kCellBytes + kCrcBytes;
}

// Built by appending: GCC 12 warns falsely (-Wrestrict, bug 105651) on some `"literal" + string` chains.
std::string tile_file_name(int tx, int ty) {
  std::string name = std::to_string(tx);
  name.append("_").append(std::to_string(ty)).append(kTileExtension);
  return name;
}

void check_geometry(const IntensityMapHeader& h, const char* who) {
  if (!(std::isfinite(h.resolution_m) && h.resolution_m > 0))
    throw std::invalid_argument(std::string(who) + ": resolution_m must be a positive number");
  if (h.tile_cells < kMinTileCells || h.tile_cells > kMaxTileCells)
    throw std::invalid_argument(std::string(who) + ": tile_cells = " + std::to_string(h.tile_cells) +
                                " is out of range [" + std::to_string(kMinTileCells) + ", " +
                                std::to_string(kMaxTileCells) + "]");
}

// Index of the global cell containing a coordinate, from q = coordinate / resolution: floor division (so
// -0.1 m is cell -1), if the tile index it falls in fits an int.
std::optional<int64_t> global_cell(double q, int tile_cells) {
  if (!std::isfinite(q)) return std::nullopt;
  // A point a few ulps past a boundary is in the cell that starts there already; one a few ulps short of
  // it moves up into it. `next - q` is exact (Sterbenz) wherever the comparison can hold, so this is
  // snapping q to the nearest integer first, without the call to round() (once per mapped point).
  double cell = std::floor(q);
  const double next = cell + 1;
  if (next - q <= kBoundarySnapUlps * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(q))) cell = next;
  // Both bounds are exact in double (|value| < 2^44 for tile_cells <= 4096).
  const double lo = double(INT_MIN) * tile_cells;
  const double hi = (double(INT_MAX) + 1) * tile_cells - 1;
  if (cell < lo || cell > hi) return std::nullopt;
  return static_cast<int64_t>(cell);
}

std::optional<CellIndex> try_cell_index(const IntensityMapHeader& h, const Eigen::Vector2d& xy) {
  // x and y divided as one pair: one vector division, each lane rounded as the scalar one is.
  const Eigen::Array2d q = xy.array() / h.resolution_m;
  const auto gx = global_cell(q.x(), h.tile_cells);
  const auto gy = global_cell(q.y(), h.tile_cells);
  if (!gx || !gy) return std::nullopt;
  const int64_t n = h.tile_cells;
  const int64_t tx = floor_div(*gx, n), ty = floor_div(*gy, n);
  return CellIndex{static_cast<int>(tx), static_cast<int>(ty), static_cast<int>(*gx - tx * n),
                   static_cast<int>(*gy - ty * n)};
}

size_t flat_index(const CellIndex& c, int tile_cells) {
  return size_t(c.cell_y) * size_t(tile_cells) + size_t(c.cell_x);
}

std::vector<IntensityMoments>& tile_or_new(std::map<std::pair<int, int>, std::vector<IntensityMoments>>& tiles,
                                           IntensityMapHeader& header, std::pair<int, int> key) {
  auto [it, inserted] = tiles.try_emplace(key);
  if (inserted) {
    it->second.resize(size_t(header.tile_cells) * size_t(header.tile_cells));
    // Kept sorted so that the header written by save() lists tiles in a stable order.
    header.tiles.insert(std::lower_bound(header.tiles.begin(), header.tiles.end(), key), key);
  }
  return it->second;
}

std::string encode_tile(int tx, int ty, int tile_cells, const std::vector<IntensityMoments>& cells) {
  std::string out;
  out.reserve(tile_file_bytes(size_t(tile_cells)));
  out.append(kTileMagic.data(), kTileMagic.size());
  put_u32(out, kTileVersion);
  put_i32(out, tx);
  put_i32(out, ty);
  put_u32(out, uint32_t(tile_cells));
  for (const IntensityMoments& m : cells) {  // row-major: y rows, x columns
    const IntensityCell c = m.to_cell();
    put_u32(out, c.count);
    put_f32(out, c.mean);
    put_f32(out, c.m2);
  }
  put_u32(out, crc32(out.data(), out.size()));
  return out;
}

// Plain scalars for people; yaml-cpp quotes the ones that would read back as something else ("null", "").
std::string header_yaml(const IntensityMapHeader& h) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kFormatName;
  out << YAML::Key << "version" << YAML::Value << kFormatVersion;
  out << YAML::Key << "world" << YAML::Value << h.world;
  out << YAML::Key << "world_hash" << YAML::Value << h.world_hash;
  out << YAML::Key << "origin" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "lat" << YAML::Value << shortest_decimal(h.origin.lat_deg);
  out << YAML::Key << "lon" << YAML::Value << shortest_decimal(h.origin.lon_deg);
  out << YAML::Key << "alt" << YAML::Value << shortest_decimal(h.origin.alt_m);
  out << YAML::EndMap;
  out << YAML::Key << "projection" << YAML::Value << kProjection;
  out << YAML::Key << "resolution_m" << YAML::Value << shortest_decimal(h.resolution_m);
  out << YAML::Key << "tile_cells" << YAML::Value << h.tile_cells;
  out << YAML::Key << "tile_size_m" << YAML::Value << shortest_decimal(h.tile_size_m());
  out << YAML::Key << "build" << YAML::Value << YAML::BeginMap;
  for (const auto& [key, value] : h.build) out << YAML::Key << key << YAML::Value << value;
  out << YAML::EndMap;
  out << YAML::Key << "tiles" << YAML::Value << YAML::BeginSeq;
  for (const auto& [tx, ty] : h.tiles) out << YAML::Flow << YAML::BeginSeq << tx << ty << YAML::EndSeq;
  out << YAML::EndSeq;
  out << YAML::EndMap;
  if (!out.good()) throw std::logic_error("intensity map header: YAML emitter error: " + out.GetLastError());
  return std::string(out.c_str()) + "\n";
}

// Reads and checks one tile file against its name and the header; every problem names the file.
std::vector<IntensityCell> load_tile(const fs::path& path, const IntensityMapHeader& h, int tx, int ty) {
  const std::string file = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(file + ": tile file is missing (map.yaml lists tile " + tile_name(tx, ty) + ")");
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in.is_open()) throw InputError(file + ": cannot open tile file");
    bytes.resize(size_t(fs::file_size(path, ec)));
    if (ec || !in.read(bytes.data(), std::streamsize(bytes.size()))) throw InputError(file + ": cannot read tile file");
  }
  const size_t expected = tile_file_bytes(size_t(h.tile_cells));
  auto truncated = [&] {
    return InputError(file + ": truncated tile file (" + std::to_string(bytes.size()) + " bytes, a tile of " +
                      std::to_string(h.tile_cells) + "x" + std::to_string(h.tile_cells) + " cells has " +
                      std::to_string(expected) + ")");
  };
  if (bytes.size() < kTileHeaderBytes) throw truncated();
  if (!std::equal(kTileMagic.begin(), kTileMagic.end(), bytes.begin()))
    throw InputError(file + ": not an intensity map tile (bad magic, expected 'LLIT')");
  size_t at = kTileMagic.size();
  const uint32_t version = get_u32(bytes, at);
  at += kWordBytes;
  if (version != kTileVersion)
    throw InputError(file + ": unsupported tile version " + std::to_string(version) + " (expected " +
                     std::to_string(kTileVersion) + ")");
  const int32_t file_tx = get_i32(bytes, at);
  at += kWordBytes;
  const int32_t file_ty = get_i32(bytes, at);
  at += kWordBytes;
  const uint32_t file_cells = get_u32(bytes, at);
  at += kWordBytes;
  if (file_cells != uint32_t(h.tile_cells))
    throw InputError(file + ": tile has tile_cells = " + std::to_string(file_cells) + " but map.yaml says " +
                     std::to_string(h.tile_cells));
  if (bytes.size() < expected) throw truncated();
  if (bytes.size() > expected)
    throw InputError(file + ": tile file has " + std::to_string(bytes.size() - expected) +
                     " unexpected bytes after its checksum");
  const uint32_t stored_crc = get_u32(bytes, expected - kCrcBytes);
  const uint32_t computed_crc = crc32(bytes.data(), expected - kCrcBytes);
  if (stored_crc != computed_crc) {
    std::ostringstream msg;
    msg << file << ": checksum mismatch (CRC-32 stored 0x" << std::hex << stored_crc << ", computed 0x" << computed_crc
        << "): the tile file is corrupt";
    throw InputError(msg.str());
  }
  if (file_tx != tx || file_ty != ty)
    throw InputError(file + ": file holds tile " + tile_name(file_tx, file_ty) + " but its name says " +
                     tile_name(tx, ty));
  std::vector<IntensityCell> cells(size_t(h.tile_cells) * size_t(h.tile_cells));
  for (size_t i = 0; i < cells.size(); ++i, at += kCellBytes) {
    IntensityCell& c = cells[i];
    c.count = get_u32(bytes, at);
    c.mean = get_f32(bytes, at + kWordBytes);
    c.m2 = get_f32(bytes, at + 2 * kWordBytes);
    // A checksum only proves the bytes are the ones written; a hand-made file can still hold nonsense.
    if (!std::isfinite(c.mean) || !std::isfinite(c.m2) || c.m2 < 0)
      throw InputError(file + ": cell (" + std::to_string(i % size_t(h.tile_cells)) + ", " +
                       std::to_string(i / size_t(h.tile_cells)) + ") holds invalid statistics");
  }
  return cells;
}

}  // namespace

// Eq. 8 of the paper updates the count, the mean and the sample variance S_sigma (n - 1 denominator)
// directly. Welford's form below is the same recursion on m2 = sum of squared deviations
// (S_sigma = m2 / (n - 1)), without the (n - 1) / n factor that is undefined for the first point.
void IntensityMoments::add(double value) {
  if (count == std::numeric_limits<uint32_t>::max())
    throw std::overflow_error("intensity cell: more points than a uint32 count holds");
  ++count;
  const double delta = value - mean;
  mean += delta / double(count);
  m2 += delta * (value - mean);
}

// Chan, Golub & LeVeque's pairwise combination: merging two partial maps is exact, not an average of
// averages.
void IntensityMoments::merge(const IntensityMoments& other) {
  const IntensityMoments b = other;  // `other` may be *this
  if (b.count == 0) return;
  if (count == 0) {
    *this = b;
    return;
  }
  const uint64_t n = uint64_t(count) + uint64_t(b.count);
  if (n > std::numeric_limits<uint32_t>::max())
    throw std::overflow_error("intensity cell: more points than a uint32 count holds");
  const double na = count, nb = b.count, total = double(n);
  const double delta = b.mean - mean;
  mean += delta * nb / total;
  m2 += b.m2 + delta * delta * na * nb / total;
  count = uint32_t(n);
}

// Computed in double, stored in float: the float rounding happens once per update here. Builders
// accumulate IntensityMoments instead, so a map is rounded once.
void IntensityCell::add(double value) {
  IntensityMoments m = IntensityMoments::from_cell(*this);
  m.add(value);
  *this = m.to_cell();
}

void IntensityCell::merge(const IntensityCell& other) {
  IntensityMoments m = IntensityMoments::from_cell(*this);
  m.merge(IntensityMoments::from_cell(other));
  *this = m.to_cell();
}

CellIndex cell_index(const IntensityMapHeader& header, const Eigen::Vector2d& xy) {
  check_geometry(header, "cell_index");
  const auto c = try_cell_index(header, xy);
  if (!c) {
    std::ostringstream msg;
    msg << "cell_index: point (" << xy.x() << ", " << xy.y() << ") has no tile index";
    throw std::out_of_range(msg.str());
  }
  return *c;
}

IntensityMapBuilder::IntensityMapBuilder(IntensityMapHeader header) : header_(std::move(header)) {
  check_geometry(header_, "IntensityMapBuilder");
  header_.tiles.clear();  // the tile list is what this builder holds, kept by tile_or_new
}

void IntensityMapBuilder::add(const Eigen::Vector2d& xy, double intensity) {
  // Organised clouds mark "no return" with NaN: not a measurement, so not part of the map.
  if (!xy.allFinite() || !std::isfinite(intensity)) return;
  // The header's geometry was checked when the builder was made; this runs once per ground point.
  const auto c = try_cell_index(header_, xy);
  if (!c) return;  // beyond any tile index an int can hold: no map covers it
  const std::pair<int, int> key{c->tile_x, c->tile_y};
  if (key != last_.key) last_.cells = &open_tile(key), last_.key = key;
  (*last_.cells)[flat_index(*c, header_.tile_cells)].add(intensity);
}

void IntensityMapBuilder::merge(const IntensityMapBuilder& other) {
  const IntensityMapHeader& o = other.header_;
  if (o.resolution_m != header_.resolution_m || o.origin.lat_deg != header_.origin.lat_deg ||
      o.origin.lon_deg != header_.origin.lon_deg)
    throw std::invalid_argument("IntensityMapBuilder::merge: maps differ in origin or resolution");
  const int64_t n = o.tile_cells, big = header_.tile_cells;
  for (const auto& [key, cells] : other.tiles_) {
    if (n == big) {
      std::vector<IntensityMoments>& mine = open_tile(key);
      for (size_t i = 0; i < mine.size(); ++i) mine[i].merge(cells[i]);
      continue;
    }
    // Tiles of another size: each cell goes to the same global cell in one of this builder's tiles.
    std::pair<int, int> last_key{INT32_MIN, INT32_MIN};
    std::vector<IntensityMoments>* mine = nullptr;
    for (int64_t cy = 0; cy < n; ++cy)
      for (int64_t cx = 0; cx < n; ++cx) {
        const IntensityMoments& m = cells[size_t(cy * n + cx)];
        if (m.count == 0) continue;
        const int64_t gx = int64_t(key.first) * n + cx, gy = int64_t(key.second) * n + cy;
        const int64_t tx = floor_div(gx, big), ty = floor_div(gy, big);
        const std::pair<int, int> target{int(tx), int(ty)};
        if (target != last_key) last_key = target, mine = &open_tile(target);
        (*mine)[size_t((gy - ty * big) * big + (gx - tx * big))].merge(m);
      }
  }
}

std::vector<IntensityMoments>& IntensityMapBuilder::open_tile(const std::pair<int, int>& key) {
  if (std::binary_search(taken_.begin(), taken_.end(), key))
    throw std::logic_error("IntensityMapBuilder: a point falls in tile " + tile_name(key.first, key.second) +
                           ", which was already handed over as finished");
  return tile_or_new(tiles_, header_, key);
}

std::vector<IntensityMoments> IntensityMapBuilder::take_tile(const std::pair<int, int>& key) {
  last_ = LastTile();
  taken_.insert(std::lower_bound(taken_.begin(), taken_.end(), key), key);
  const auto it = tiles_.find(key);
  if (it == tiles_.end()) return {};
  std::vector<IntensityMoments> cells = std::move(it->second);
  tiles_.erase(it);
  return cells;
}

std::optional<IntensityCell> IntensityMapBuilder::cell(const Eigen::Vector2d& xy) const {
  const auto c = try_cell_index(header_, xy);
  if (!c) return std::nullopt;
  const auto it = tiles_.find({c->tile_x, c->tile_y});
  if (it == tiles_.end()) return std::nullopt;
  const IntensityMoments& m = it->second[flat_index(*c, header_.tile_cells)];
  if (m.count == 0) return std::nullopt;
  return m.to_cell();
}

void IntensityMapBuilder::save(const std::string& dir) const {
  if (!taken_.empty())
    throw std::logic_error("IntensityMapBuilder::save: tiles were handed over; write them as they come");
  IntensityMapWriter writer(dir);
  for (const auto& [key, cells] : tiles_) writer.write_tile(header_, key, cells);
  writer.finish(header_);
}

IntensityMapWriter::IntensityMapWriter(const std::string& dir) : dir_(dir) {
  const fs::path root(dir), tiles_dir = root / kTilesDir;
  std::error_code ec;
  fs::create_directories(tiles_dir, ec);
  if (ec) throw InputError(tiles_dir.string() + ": cannot create map directory: " + ec.message());
  // Without a header a half-replaced map fails loudly instead of mixing old and new tiles.
  fs::remove(root / kHeaderFile, ec);
  if (ec) throw InputError((root / kHeaderFile).string() + ": cannot remove the previous map header: " + ec.message());
  // Stale tiles of a previous map would otherwise sit unlisted next to the new ones. Only our own
  // files go: anything else a user keeps there is left alone.
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(tiles_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.ends_with(kTileExtension) || name.ends_with(std::string(kTileExtension) + kTempSuffix))
      stale.push_back(it->path());
  }
  if (ec) throw InputError(tiles_dir.string() + ": cannot list directory: " + ec.message());
  for (const fs::path& path : stale)
    if (fs::remove(path, ec); ec) throw InputError(path.string() + ": cannot remove stale tile: " + ec.message());
}

void IntensityMapWriter::write_tile(const IntensityMapHeader& header, const std::pair<int, int>& key,
                                    const std::vector<IntensityMoments>& cells) {
  if (cells.size() != size_t(header.tile_cells) * size_t(header.tile_cells))
    throw std::invalid_argument("IntensityMapWriter: tile " + tile_name(key.first, key.second) + " has " +
                                std::to_string(cells.size()) + " cells, not tile_cells^2");
  write_file_atomically(fs::path(dir_) / kTilesDir / tile_file_name(key.first, key.second),
                        encode_tile(key.first, key.second, header.tile_cells, cells));
  written_.insert(std::lower_bound(written_.begin(), written_.end(), key), key);
}

void IntensityMapWriter::finish(const IntensityMapHeader& header) {
  std::vector<std::pair<int, int>> listed = header.tiles;
  std::sort(listed.begin(), listed.end());
  if (listed != written_)
    throw std::logic_error("IntensityMapWriter::finish: the header lists other tiles than were written");
  write_file_atomically(fs::path(dir_) / kHeaderFile, header_yaml(header));  // last: the map exists once it is whole
}

IntensityMapHeader read_intensity_map_header(const std::string& dir) {
  const YamlReader yaml = YamlReader::open((fs::path(dir) / kHeaderFile).string());
  YamlMap root(yaml, yaml.root(), "intensity map header");
  IntensityMapHeader h;

  read_format_and_version(yaml, root, kFormatName, kFormatVersion);

  h.world = yaml.string(root.required("world"), "world");
  h.world_hash = yaml.string(root.required("world_hash"), "world_hash");

  YamlMap origin(yaml, root.required("origin"), "origin");
  h.origin.lat_deg = yaml.number_in(origin.required("lat"), "origin.lat", -kMaxLatitudeDeg, kMaxLatitudeDeg);
  h.origin.lon_deg = yaml.number_in(origin.required("lon"), "origin.lon", -kMaxLongitudeDeg, kMaxLongitudeDeg);
  h.origin.alt_m = yaml.number(origin.required("alt"), "origin.alt");
  origin.done();

  const YAML::Node projection = root.required("projection");
  if (yaml.string(projection, "projection") != kProjection)
    yaml.fail(projection, "projection '" + projection.Scalar() + "' is not supported (expected '" + kProjection + "')");

  const YAML::Node resolution = root.required("resolution_m");
  h.resolution_m = yaml.number(resolution, "resolution_m");
  if (h.resolution_m <= 0) yaml.fail(resolution, "resolution_m = " + resolution.Scalar() + " must be > 0");
  h.tile_cells = int(yaml.integer_in(root.required("tile_cells"), "tile_cells", kMinTileCells, kMaxTileCells));
  const YAML::Node tile_size = root.required("tile_size_m");
  const double size = yaml.number(tile_size, "tile_size_m");
  if (std::fabs(size - h.tile_size_m()) > kTileSizeRelativeTolerance * h.tile_size_m())
    yaml.fail(tile_size, "tile_size_m = " + tile_size.Scalar() +
                             " does not match resolution_m * tile_cells = " + shortest_decimal(h.tile_size_m()));

  const YAML::Node build = root.required("build");
  yaml.expect_map(build, "build");
  for (const auto& entry : build)
    h.build[yaml.string(entry.first, "build key")] = yaml.string(entry.second, "build value");

  const YAML::Node tiles = root.required("tiles");
  root.done();
  h.tiles = read_tile_list(yaml, tiles);
  return h;
}

IntensityMap::IntensityMap(const std::string& dir, size_t max_cached_tiles)
    : dir_(dir), header_(read_intensity_map_header(dir)), max_cached_(max_cached_tiles) {
  if (max_cached_ == 0) throw std::invalid_argument("IntensityMap: max_cached_tiles must be at least 1");
  for (const auto& key : header_.tiles) present_[key] = true;
}

std::optional<IntensityCell> IntensityMap::cell(const Eigen::Vector2d& xy) {
  const auto c = try_cell_index(header_, xy);
  if (!c) return std::nullopt;
  const std::vector<IntensityCell>* cells = tile(c->tile_x, c->tile_y);
  if (cells == nullptr) return std::nullopt;
  const IntensityCell& value = (*cells)[flat_index(*c, header_.tile_cells)];
  if (value.count == 0) return std::nullopt;
  return value;
}

size_t IntensityMap::preload(const Eigen::Vector2d& centre, double half_extent) {
  const auto lo = try_cell_index(header_, centre - Eigen::Vector2d::Constant(half_extent));
  const auto hi = try_cell_index(header_, centre + Eigen::Vector2d::Constant(half_extent));
  if (!lo || !hi) return 0;
  size_t read = 0;
  for (int ty = lo->tile_y; ty <= hi->tile_y; ++ty)
    for (int tx = lo->tile_x; tx <= hi->tile_x; ++tx) {
      if (read >= max_cached_) return read;  // more would evict the first
      if (tile(tx, ty) != nullptr) ++read;
    }
  return read;
}

// The returned pointer is valid until the next call (which may evict it).
const std::vector<IntensityCell>* IntensityMap::tile(int tx, int ty) {
  const std::pair<int, int> key{tx, ty};
  if (key == last_key_) return last_tile_;  // still cached: only a lookup of another tile evicts
  last_key_ = key;
  last_tile_ = lookup_tile(key);
  return last_tile_;
}

const std::vector<IntensityCell>* IntensityMap::lookup_tile(const std::pair<int, int>& key) {
  const auto [tx, ty] = key;
  if (present_.find(key) == present_.end()) return nullptr;  // not in the map: no data there
  if (auto hit = cache_.find(key); hit != cache_.end()) {
    lru_.splice(lru_.begin(), lru_, hit->second.second);
    return &hit->second.first;
  }
  // Loaded before touching the cache, so a bad tile leaves the cache as it was.
  // On a bad tile last_key_ must not keep pointing at it.
  last_key_ = {INT32_MIN, INT32_MIN};
  std::vector<IntensityCell> cells = load_tile(fs::path(dir_) / kTilesDir / tile_file_name(tx, ty), header_, tx, ty);
  last_key_ = key;
  ++loads_;
  if (cache_.size() >= max_cached_) {
    cache_.erase(lru_.back());
    lru_.pop_back();
  }
  lru_.push_front(key);
  const auto inserted = cache_.emplace(key, std::make_pair(std::move(cells), lru_.begin())).first;
  return &inserted->second.first;
}

}  // namespace lidarloop
