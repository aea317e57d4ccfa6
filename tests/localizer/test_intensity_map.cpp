// The intensity layer (section 2.2.2, Eq. 8): running statistics against a two-pass computation, cell
// indexing with negative coordinates and tile boundaries, the tile file format, lazy loading with a
// bounded LRU cache, and every kind of bad map on disk.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "common/input_error.hpp"
#include "localizer/intensity_map.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr int kValues = 10000;
constexpr uint32_t kSeed = 20240611;
constexpr double kTwoPassTolerance = 1e-6;  // relative
constexpr double kMergeTolerance = 1e-5;    // relative
// The smallest allowed tile keeps files tiny and tests fast; 0.5 m cells make boundaries exact decimals.
constexpr int kSmallTileCells = 16;
constexpr double kCoarseResolution = 0.5;
constexpr double kSmallTileSize = kSmallTileCells * kCoarseResolution;  // 8 m
const Geodetic kCampus{31.2856, 121.2147, 4.0};

// ---------------------------------------------------------------------------------------------------
// Helpers

struct TwoPass {
  double mean = 0, variance = 0;  // population variance (divide by n), as IntensityCell::variance()
};

TwoPass two_pass(const std::vector<double>& v) {
  TwoPass r;
  for (double x : v) r.mean += x;
  r.mean /= double(v.size());
  for (double x : v) r.variance += (x - r.mean) * (x - r.mean);
  r.variance /= double(v.size());
  return r;
}

std::vector<double> normal_values(double mean, double sd, int n = kValues, uint32_t seed = kSeed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> dist(mean, sd);
  std::vector<double> v(static_cast<size_t>(n));
  for (double& x : v) x = dist(rng);
  return v;
}

double relative_error(double value, double truth) { return std::fabs(value - truth) / std::fabs(truth); }

IntensityMapHeader small_header() {
  IntensityMapHeader h;
  h.world = "campus";
  h.world_hash = "9f86d081884c7d65";
  h.origin = kCampus;
  h.resolution_m = kCoarseResolution;
  h.tile_cells = kSmallTileCells;
  h.build = {{"lidar", "hdl32e"}, {"passes", "2"}, {"scenario", "scenarios/campus loop.yaml"}};
  return h;
}

// Centre of global cell (gx, gy) of a header's grid.
Eigen::Vector2d cell_centre(const IntensityMapHeader& h, int gx, int gy) {
  return {(gx + 0.5) * h.resolution_m, (gy + 0.5) * h.resolution_m};
}

// Intensity that depends on position (paint vs asphalt) plus noise, as a mapping drive would see.
struct PointStream {
  std::vector<Eigen::Vector2d> xy;
  std::vector<double> intensity;
};

PointStream random_points(int n, double half_extent, uint32_t seed = kSeed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-half_extent, half_extent);
  std::normal_distribution<double> noise(0, 4);
  PointStream s;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d p(pos(rng), pos(rng));
    const double paint = std::fmod(std::fabs(p.x()), 3.0) < 0.5 ? 60.0 : 0.0;
    s.xy.push_back(p);
    s.intensity.push_back(std::clamp(20.0 + paint + noise(rng), 0.0, 255.0));
  }
  return s;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

void replace_in_file(const fs::path& p, const std::string& from, const std::string& to) {
  std::string text = read_bytes(p);
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << "'" << from << "' not in " << p;
  text.replace(at, from.size(), to);
  write_bytes(p, text);
}

uint32_t le32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}

// Bit-by-bit CRC-32 (IEEE), independent of the table-driven one under test.
uint32_t reference_crc32(const std::string& bytes, size_t length) {
  uint32_t crc = 0xFFFFFFFFu;
  for (size_t i = 0; i < length; ++i) {
    crc ^= static_cast<unsigned char>(bytes[i]);
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// A folder of its own per test (and per process: other builds may run the same tests at once).
class IntensityMapTempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("lidarloop_intensity_" + std::string(info->test_suite_name()) + "_" +
                                             info->name() + "_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string dir() const { return dir_.string(); }
  fs::path tile_path(int tx, int ty) const {
    return dir_ / "tiles" / (std::to_string(tx) + "_" + std::to_string(ty) + ".tile");
  }
  fs::path dir_;
};

// A builder covering tiles (0, 0) and (1, 0) only, saved into the test's folder.
IntensityMapBuilder two_tile_map() {
  IntensityMapBuilder b(small_header());
  for (int i = 0; i < 200; ++i) {
    b.add({0.1 + 0.035 * i, 1.0 + 0.01 * i}, 10.0 + i % 7);
    b.add({kSmallTileSize + 0.1 + 0.035 * i, 2.0}, 50.0 + i % 5);
  }
  return b;
}

// ---------------------------------------------------------------------------------------------------
// 1. Eq. 8 against a two-pass computation

TEST(IntensityMapStats, SmallKnownValues) {
  // 2 4 4 4 5 5 7 9: mean 5, population variance 4; every intermediate is exact in float.
  IntensityCell c;
  for (double x : {2, 4, 4, 4, 5, 5, 7, 9}) c.add(x);
  EXPECT_EQ(c.count, 8u);
  EXPECT_EQ(c.mean, 5.0f);
  EXPECT_EQ(c.m2, 32.0f);
  EXPECT_EQ(c.variance(), 4.0);
  EXPECT_EQ(IntensityCell{}.variance(), 0.0);
}

// Checks the double accumulator, a builder's cell (rounded to float once) and the data's difficulty.
void expect_matches_two_pass(double mean, double sd) {
  SCOPED_TRACE("mean " + std::to_string(mean) + ", sd " + std::to_string(sd));
  const std::vector<double> v = normal_values(mean, sd);
  const TwoPass truth = two_pass(v);

  IntensityMoments m;
  IntensityMapBuilder builder(small_header());
  const Eigen::Vector2d where(-3.3, 7.7);
  for (double x : v) {
    m.add(x);
    builder.add(where, x);
  }
  EXPECT_EQ(m.count, uint32_t(kValues));
  EXPECT_LT(relative_error(m.mean, truth.mean), kTwoPassTolerance);
  EXPECT_LT(relative_error(m.variance(), truth.variance), kTwoPassTolerance);

  const auto cell = builder.cell(where);
  ASSERT_TRUE(cell.has_value());
  EXPECT_EQ(cell->count, uint32_t(kValues));
  EXPECT_LT(relative_error(cell->mean, truth.mean), kTwoPassTolerance);
  EXPECT_LT(relative_error(cell->variance(), truth.variance), kTwoPassTolerance);
}

TEST(IntensityMapStats, RunningMeanAndVarianceMatchTwoPass) { expect_matches_two_pass(40, 15); }

TEST(IntensityMapStats, LargeOffsetWhereNaiveSumOfSquaresFails) {
  expect_matches_two_pass(1e4, 1);
  expect_matches_two_pass(1e8, 1);

  // The data really is hard: sum x^2 - (sum x)^2 / n loses everything in float at 1e4 and in double
  // at 1e8, the precisions a map stores and computes in.
  auto naive = [](const std::vector<double>& v, auto zero) {
    decltype(zero) s = 0, s2 = 0;
    for (double x : v) {
      s += decltype(zero)(x);
      s2 += decltype(zero)(x) * decltype(zero)(x);
    }
    const double n = double(v.size());
    return (double(s2) - double(s) * double(s) / n) / n;
  };
  const std::vector<double> offset4 = normal_values(1e4, 1), offset8 = normal_values(1e8, 1);
  EXPECT_GT(relative_error(naive(offset4, 0.0f), two_pass(offset4).variance), 0.5);
  EXPECT_GT(relative_error(naive(offset8, 0.0), two_pass(offset8).variance), 0.5);
}

TEST(IntensityMapStats, FloatCellRoundsAtEveryUpdate) {
  // IntensityCell::add stores float after each point, so rounding accumulates like a random walk
  // (~sqrt(n) ulps): good to ~1e-5 on realistic intensities, which is why builders accumulate in double.
  constexpr double kFloatPerUpdateTolerance = 2e-5;
  const std::vector<double> v = normal_values(40, 15);
  const TwoPass truth = two_pass(v);
  IntensityCell c;
  for (double x : v) c.add(x);
  EXPECT_EQ(c.count, uint32_t(kValues));
  EXPECT_LT(relative_error(c.mean, truth.mean), kFloatPerUpdateTolerance);
  EXPECT_LT(relative_error(c.variance(), truth.variance), kFloatPerUpdateTolerance);
}

TEST(IntensityMapStats, PaperEq8RecursionIsWelford) {
  // Eq. 8 as printed updates the sample variance (n - 1 denominator) directly; from the second point on
  // it must agree with Welford's m2 / (n - 1).
  const std::vector<double> v = normal_values(40, 15, 1000);
  double n = 1, mean = v[0], sigma = 0;
  IntensityMoments m;
  m.add(v[0]);
  for (size_t i = 1; i < v.size(); ++i) {
    const double r = v[i];
    const double new_sigma = (n - 1) / n * sigma + (r - mean) * (r - mean) / (n + 1);
    mean += (r - mean) / (n + 1);
    sigma = new_sigma;
    n += 1;
    m.add(r);
  }
  EXPECT_NEAR(m.mean, mean, 1e-12 * std::fabs(mean));
  EXPECT_NEAR(m.m2 / (m.count - 1), sigma, 1e-9 * sigma);
}

TEST(IntensityMapStats, MergeEqualsOneStream) {
  const std::vector<double> v = normal_values(40, 15);
  constexpr size_t kSplit = 3000;  // unequal parts
  IntensityMoments all, a, b;
  for (size_t i = 0; i < v.size(); ++i) {
    all.add(v[i]);
    (i < kSplit ? a : b).add(v[i]);
  }
  a.merge(b);
  EXPECT_EQ(a.count, all.count);
  EXPECT_NEAR(a.mean, all.mean, 1e-12 * all.mean);
  EXPECT_NEAR(a.m2, all.m2, 1e-10 * all.m2);

  // Float cells: {1, 2, 3} + {4, 5} = 1..5, mean 3, m2 = 4 + 1 + 0 + 1 + 4.
  IntensityCell x, y;
  for (double value : {1, 2, 3}) x.add(value);
  for (double value : {4, 5}) y.add(value);
  x.merge(y);
  EXPECT_EQ(x.count, 5u);
  EXPECT_EQ(x.mean, 3.0f);
  EXPECT_EQ(x.m2, 10.0f);
}

TEST(IntensityMapStats, MergeWithEmptyCells) {
  IntensityCell data;
  for (double value : {10, 20, 30}) data.add(value);
  IntensityCell empty;

  IntensityCell left = empty;
  left.merge(data);
  EXPECT_EQ(left.count, data.count);
  EXPECT_EQ(left.mean, data.mean);
  EXPECT_EQ(left.m2, data.m2);

  IntensityCell right = data;
  right.merge(empty);
  EXPECT_EQ(right.count, data.count);
  EXPECT_EQ(right.mean, data.mean);
  EXPECT_EQ(right.m2, data.m2);

  IntensityCell none;
  none.merge(empty);
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.mean, 0.0f);
  EXPECT_EQ(none.variance(), 0.0);

  IntensityMoments self;  // merging with itself doubles the count, keeps mean and variance
  for (double value : {10, 20, 30}) self.add(value);
  self.merge(self);
  EXPECT_EQ(self.count, 6u);
  EXPECT_DOUBLE_EQ(self.mean, 20.0);
  EXPECT_DOUBLE_EQ(self.variance(), 200.0 / 3.0);
}

// ---------------------------------------------------------------------------------------------------
// 2. A map built in two halves and merged equals one built at once

TEST(IntensityMapBuild, TwoHalvesMergedEqualOneStream) {
  const IntensityMapHeader h = small_header();
  constexpr int kPoints = 40000;
  constexpr double kHalfExtent = 13;  // spans tiles -2..1 on both axes
  const PointStream s = random_points(kPoints, kHalfExtent);
  IntensityMapBuilder whole(h), first(h), second(h);
  for (size_t i = 0; i < s.xy.size(); ++i) {
    whole.add(s.xy[i], s.intensity[i]);
    (i < s.xy.size() / 2 ? first : second).add(s.xy[i], s.intensity[i]);
  }
  first.merge(second);
  EXPECT_EQ(first.tile_count(), whole.tile_count());
  EXPECT_EQ(first.header().tiles, whole.header().tiles);

  const int span = int(std::ceil(kHalfExtent / h.resolution_m)) + 1;
  size_t cells = 0, points = 0;
  for (int gx = -span; gx <= span; ++gx)
    for (int gy = -span; gy <= span; ++gy) {
      const Eigen::Vector2d p = cell_centre(h, gx, gy);
      const auto a = first.cell(p), b = whole.cell(p);
      ASSERT_EQ(a.has_value(), b.has_value()) << "cell " << gx << ", " << gy;
      if (!b) continue;
      ++cells;
      points += b->count;
      ASSERT_EQ(a->count, b->count);
      EXPECT_NEAR(a->mean, b->mean, kMergeTolerance * std::fabs(b->mean));
      // A single point has variance 0 both ways; the floor only covers that case.
      EXPECT_NEAR(a->variance(), b->variance(), kMergeTolerance * b->variance() + 1e-12);
    }
  EXPECT_EQ(points, size_t(kPoints));  // every point landed in exactly one visited cell
  const double area_cells = std::pow(2 * kHalfExtent / h.resolution_m, 2);
  EXPECT_GT(double(cells), 0.99 * area_cells);  // ~15 points a cell: nearly all of them hold data
}

// A builder of small tiles (what one part of a mapping drive accumulates) merges into a builder of
// large ones cell for cell: the same as merging the same points held in large tiles.
TEST(IntensityMapBuild, MergeOfSmallerTilesEqualsMergeOfTheSameTiles) {
  const IntensityMapHeader h = small_header();
  IntensityMapHeader blocks = h;
  blocks.tile_cells = kSmallTileCells / 2;
  const PointStream s = random_points(20000, 13);
  IntensityMapBuilder base(h), part_same(h), part_small(blocks);
  for (size_t i = 0; i < s.xy.size(); ++i)
    (i % 3 == 0 ? base : i % 3 == 1 ? part_same : part_small).add(s.xy[i], s.intensity[i]);
  IntensityMapBuilder a = base, b = base;
  a.merge(part_small);
  b.merge(part_same);
  b.merge(part_small);
  a.merge(part_same);  // the other order: Chan's merge rounds differently, the counts agree
  EXPECT_EQ(a.header().tiles, b.header().tiles);
  const int span = int(std::ceil(13 / h.resolution_m)) + 1;
  for (int gx = -span; gx <= span; ++gx)
    for (int gy = -span; gy <= span; ++gy) {
      const auto x = a.cell(cell_centre(h, gx, gy)), y = b.cell(cell_centre(h, gx, gy));
      ASSERT_EQ(x.has_value(), y.has_value());
      if (!x) continue;
      ASSERT_EQ(x->count, y->count);
      EXPECT_NEAR(x->mean, y->mean, kMergeTolerance * std::fabs(y->mean));
    }
}

TEST(IntensityMapBuild, MergeRefusesADifferentGrid) {
  IntensityMapHeader other = small_header();
  other.resolution_m = 0.25;
  IntensityMapBuilder a(small_header()), b(other);
  EXPECT_THROW(a.merge(b), std::invalid_argument);
  IntensityMapHeader moved = small_header();
  moved.origin.lat_deg += 0.01;
  IntensityMapBuilder c(moved);
  EXPECT_THROW(a.merge(c), std::invalid_argument);
}

TEST(IntensityMapBuild, NoReturnPointsAreNotMeasurements) {
  IntensityMapBuilder b(small_header());
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  b.add({kNan, 1.0}, 30);
  b.add({1.0, 1.0}, kNan);
  EXPECT_EQ(b.tile_count(), 0u);
  EXPECT_FALSE(b.cell({1.0, 1.0}).has_value());
}

TEST(IntensityMapBuild, RejectsBadGeometry) {
  IntensityMapHeader h = small_header();
  h.resolution_m = 0;
  EXPECT_THROW(IntensityMapBuilder{h}, std::invalid_argument);
  h = small_header();
  h.tile_cells = 4;
  EXPECT_THROW(IntensityMapBuilder{h}, std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------
// 3. Cell indexing

void expect_index(const IntensityMapHeader& h, Eigen::Vector2d xy, CellIndex want) {
  const CellIndex got = cell_index(h, xy);
  EXPECT_EQ(got.tile_x, want.tile_x) << "at " << xy.transpose();
  EXPECT_EQ(got.tile_y, want.tile_y) << "at " << xy.transpose();
  EXPECT_EQ(got.cell_x, want.cell_x) << "at " << xy.transpose();
  EXPECT_EQ(got.cell_y, want.cell_y) << "at " << xy.transpose();
}

TEST(IntensityMapIndex, PositiveAndNegativeCoordinates) {
  const IntensityMapHeader h = small_header();  // 0.5 m cells, 16 per 8 m tile
  const int last = kSmallTileCells - 1;
  expect_index(h, {0, 0}, {0, 0, 0, 0});
  expect_index(h, {0.49, 0.51}, {0, 0, 0, 1});  // x east = column, y north = row
  expect_index(h, {3.2, 7.9}, {0, 0, 6, 15});
  expect_index(h, {-1e-9, 0}, {-1, 0, last, 0});         // just west of the origin: tile -1
  expect_index(h, {-0.5, -0.25}, {-1, -1, last, last});  // -0.5 starts cell -1
  expect_index(h, {-0.5000001, 0}, {-1, 0, last - 1, 0});
  expect_index(h, {-kSmallTileSize, 0}, {-1, 0, 0, 0});  // tile -1 covers [-8, 0)
  expect_index(h, {-kSmallTileSize - 1e-9, 0}, {-2, 0, last, 0});
  expect_index(h, {-100.25, 37.0}, {-13, 4, 7, 10});  // -100.25 / 0.5 = -200.5 -> cell -201
}

TEST(IntensityMapIndex, ExactTileBoundaries) {
  const IntensityMapHeader h = small_header();
  const int last = kSmallTileCells - 1;
  expect_index(h, {kSmallTileSize, 0}, {1, 0, 0, 0});  // [8, 16) is tile 1
  expect_index(h, {kSmallTileSize - 1e-9, 0}, {0, 0, last, 0});
  expect_index(h, {-3, kSmallTileSize}, {-1, 1, 10, 0});
  expect_index(h, {2 * kSmallTileSize, -2 * kSmallTileSize}, {2, -2, 0, 0});

  // The default grid (0.2 m, 320 cells, 64 m tiles): 0.2 is not exact in binary, boundaries still are.
  const IntensityMapHeader d;
  const double size = d.tile_size_m();
  expect_index(d, {size, 3 * size}, {1, 3, 0, 0});
  expect_index(d, {-size, -7 * size}, {-1, -7, 0, 0});
  expect_index(d, {0.6, -0.6}, {0, -1, 3, 317});  // 0.6 / 0.2 = 2.9999999999999996 in double
}

TEST(IntensityMapIndex, UnrepresentablePoints) {
  const IntensityMapHeader h = small_header();
  EXPECT_THROW(cell_index(h, {1e30, 0}), std::out_of_range);
  IntensityMapBuilder b(h);
  EXPECT_FALSE(b.cell({1e30, 0}).has_value());
  EXPECT_FALSE(b.cell({std::numeric_limits<double>::infinity(), 0}).has_value());
}

// ---------------------------------------------------------------------------------------------------
// 4. Save -> load

using IntensityMapFiles = IntensityMapTempDir;

// Handing tiles over one by one to a writer gives the files save() writes, byte for byte; a point
// that falls in a tile already handed over is a logic error, and so is saving such a builder.
TEST_F(IntensityMapFiles, TilesHandedOverToAWriterEqualSave) {
  const IntensityMapHeader h = small_header();
  const PointStream s = random_points(20000, 12);
  IntensityMapBuilder whole(h), streamed(h);
  for (size_t i = 0; i < s.xy.size(); ++i) whole.add(s.xy[i], s.intensity[i]), streamed.add(s.xy[i], s.intensity[i]);
  whole.save(dir() + "/whole");
  IntensityMapWriter writer(dir() + "/streamed");
  for (const auto& key : std::vector<std::pair<int, int>>(streamed.header().tiles))
    writer.write_tile(streamed.header(), key, streamed.take_tile(key));
  EXPECT_EQ(streamed.tile_count(), 0u);
  writer.finish(streamed.header());
  for (const auto& f : fs::recursive_directory_iterator(dir() + "/whole")) {
    if (!f.is_regular_file()) continue;
    const fs::path other = fs::path(dir() + "/streamed") / fs::relative(f.path(), dir() + "/whole");
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(fs::file_size(other), f.file_size());
    std::ifstream x(f.path(), std::ios::binary), y(other, std::ios::binary);
    EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(x), {}, std::istreambuf_iterator<char>(y))) << other;
  }
  EXPECT_THROW(streamed.add(s.xy[0], 10), std::logic_error);
  EXPECT_THROW(streamed.save(dir() + "/again"), std::logic_error);
}

TEST_F(IntensityMapFiles, SaveLoadRoundTrip) {
  const IntensityMapHeader h = small_header();
  constexpr double kHalfExtent = 12;
  const PointStream s = random_points(20000, kHalfExtent);
  IntensityMapBuilder b(h);
  for (size_t i = 0; i < s.xy.size(); ++i) b.add(s.xy[i], s.intensity[i]);
  b.save(dir());

  IntensityMap map(dir(), 4);
  const IntensityMapHeader& got = map.header();
  EXPECT_EQ(got.world, h.world);
  EXPECT_EQ(got.world_hash, h.world_hash);
  EXPECT_EQ(got.origin.lat_deg, h.origin.lat_deg);  // written as the shortest exact decimal
  EXPECT_EQ(got.origin.lon_deg, h.origin.lon_deg);
  EXPECT_EQ(got.origin.alt_m, h.origin.alt_m);
  EXPECT_EQ(got.resolution_m, h.resolution_m);
  EXPECT_EQ(got.tile_cells, h.tile_cells);
  EXPECT_EQ(got.build, h.build);
  const std::vector<std::pair<int, int>> want_tiles = {{-2, -2}, {-2, -1}, {-2, 0}, {-2, 1}, {-1, -2}, {-1, -1},
                                                       {-1, 0},  {-1, 1},  {0, -2}, {0, -1}, {0, 0},   {0, 1},
                                                       {1, -2},  {1, -1},  {1, 0},  {1, 1}};
  EXPECT_EQ(b.header().tiles, want_tiles);
  EXPECT_EQ(got.tiles, want_tiles);

  // Every cell of every tile, and a ring around them that must stay empty.
  size_t cells = 0;
  for (int gx = -3 * kSmallTileCells; gx < 3 * kSmallTileCells; ++gx)
    for (int gy = -3 * kSmallTileCells; gy < 3 * kSmallTileCells; ++gy) {
      const Eigen::Vector2d p = cell_centre(h, gx, gy);
      const auto want = b.cell(p);
      const auto have = map.cell(p);
      ASSERT_EQ(have.has_value(), want.has_value()) << "cell " << gx << ", " << gy;
      if (!want) continue;
      ++cells;
      EXPECT_EQ(have->count, want->count);
      EXPECT_EQ(have->mean, want->mean);  // float exact
      EXPECT_EQ(have->m2, want->m2);
    }
  EXPECT_GT(cells, size_t(1000));

  // Human readable.
  const std::string yaml = read_bytes(dir_ / "map.yaml");
  EXPECT_NE(yaml.find("format: lidarloop-intensity-map"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("projection: transverse_mercator"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution_m: 0.5"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("tile_size_m: 8"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("lat: 31.2856"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("- [-2, -2]"), std::string::npos) << yaml;
}

TEST_F(IntensityMapFiles, TileFileLayout) {
  IntensityMapBuilder b(small_header());
  // Global cell (-13, 5) = tile (-1, 0), cell (3, 5).
  const Eigen::Vector2d where = cell_centre(b.header(), -13, 5);
  for (double x : {11, 12, 16}) b.add(where, x);
  b.save(dir());

  const std::string bytes = read_bytes(tile_path(-1, 0));
  constexpr size_t kHeader = 20, kCell = 12, kCrc = 4;
  ASSERT_EQ(bytes.size(), kHeader + kSmallTileCells * kSmallTileCells * kCell + kCrc);
  EXPECT_EQ(bytes.substr(0, 4), "LLIT");
  EXPECT_EQ(le32(bytes, 4), 1u);
  EXPECT_EQ(int32_t(le32(bytes, 8)), -1);
  EXPECT_EQ(int32_t(le32(bytes, 12)), 0);
  EXPECT_EQ(le32(bytes, 16), uint32_t(kSmallTileCells));
  const size_t at = kHeader + (5 * kSmallTileCells + 3) * kCell;  // row-major: y rows, x columns
  EXPECT_EQ(le32(bytes, at), 3u);
  const uint32_t mean_bits = le32(bytes, at + 4), m2_bits = le32(bytes, at + 8);
  float mean = 0, m2 = 0;
  std::memcpy(&mean, &mean_bits, sizeof mean);
  std::memcpy(&m2, &m2_bits, sizeof m2);
  EXPECT_EQ(mean, 13.0f);
  EXPECT_EQ(m2, 14.0f);  // 4 + 1 + 9

  // Standard CRC-32: the reference implementation gives the catalogue check value, and the file's.
  EXPECT_EQ(reference_crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(le32(bytes, bytes.size() - kCrc), reference_crc32(bytes, bytes.size() - kCrc));
}

TEST_F(IntensityMapFiles, SaveReplacesAPreviousMap) {
  IntensityMapBuilder old_map(small_header());
  old_map.add({-50, -50}, 10);
  old_map.add({50, 50}, 10);
  old_map.save(dir());
  write_bytes(dir_ / "tiles" / "notes.txt", "kept");  // not ours: left alone

  IntensityMapBuilder new_map(small_header());
  new_map.add({1, 1}, 42);
  new_map.save(dir());

  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir_ / "tiles")) files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"0_0.tile", "notes.txt"}));
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_NE(entry.path().extension(), ".tmp");

  IntensityMap map(dir());
  EXPECT_FALSE(map.cell({-50, -50}).has_value());
  EXPECT_FALSE(map.cell({50, 50}).has_value());
  ASSERT_TRUE(map.cell({1, 1}).has_value());
  EXPECT_EQ(map.cell({1, 1})->mean, 42.0f);
}

TEST_F(IntensityMapFiles, EmptyMap) {
  IntensityMapBuilder(small_header()).save(dir());
  IntensityMap map(dir());
  EXPECT_TRUE(map.header().tiles.empty());
  EXPECT_FALSE(map.cell({0, 0}).has_value());
  EXPECT_EQ(map.tiles_loaded(), 0u);
}

// ---------------------------------------------------------------------------------------------------
// 5 and 7. Lazy loading, LRU cache, bounded memory

using IntensityMapCache = IntensityMapTempDir;

TEST_F(IntensityMapCache, LeastRecentlyUsedTileIsEvicted) {
  IntensityMapBuilder b(small_header());
  const Eigen::Vector2d a(1, 1), bb(kSmallTileSize + 1, 1), c(2 * kSmallTileSize + 1, 1);
  for (const auto& p : {a, bb, c}) b.add(p, 30);
  b.save(dir());

  IntensityMap map(dir(), 2);
  EXPECT_EQ(map.tiles_loaded(), 0u);  // nothing read before it is needed
  constexpr int kRounds = 3;
  for (int round = 0; round < kRounds; ++round)
    for (const auto& p : {a, bb, c}) {
      ASSERT_TRUE(map.cell(p).has_value());
      EXPECT_LE(map.cached_tiles(), 2u);
    }
  EXPECT_EQ(map.tiles_loaded(), size_t(3 * kRounds));  // a cycle of 3 through 2 slots misses every time

  // LRU, not FIFO: touching a keeps it; b (least recently used) goes when c comes.
  IntensityMap lru(dir(), 2);
  lru.cell(a);
  lru.cell(bb);
  lru.cell(a);
  lru.cell(c);
  EXPECT_EQ(lru.tiles_loaded(), 3u);
  lru.cell(a);
  EXPECT_EQ(lru.tiles_loaded(), 3u);
  lru.cell(bb);
  EXPECT_EQ(lru.tiles_loaded(), 4u);

  IntensityMap one(dir(), 2);
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(one.cell({1 + 0.01 * i, 1}).has_value() == (i < 50));
  EXPECT_EQ(one.tiles_loaded(), 1u);
  EXPECT_EQ(one.cached_tiles(), 1u);
}

TEST_F(IntensityMapCache, UnlistedTilesAndEmptyCellsHaveNoData) {
  two_tile_map().save(dir());
  IntensityMap map(dir());
  EXPECT_FALSE(map.cell({-1, -1}).has_value());  // tile (-1, -1) is not in the map
  EXPECT_EQ(map.tiles_loaded(), 0u);
  EXPECT_FALSE(map.cell({7.9, 7.9}).has_value());  // tile (0, 0) is, this cell got no point
  EXPECT_EQ(map.tiles_loaded(), 1u);
  EXPECT_TRUE(map.cell({0.1, 1.0}).has_value());
  EXPECT_THROW((IntensityMap{dir(), 0}), std::invalid_argument);
}

TEST_F(IntensityMapCache, MemoryStaysBoundedOnALargeMap) {
  constexpr int kTilesX = 8, kTilesY = 5, kMaxCached = 4;
  IntensityMapHeader h = small_header();
  h.tile_cells = 8;  // the smallest allowed tile
  h.resolution_m = 1.0;
  IntensityMapBuilder b(h);
  for (int tx = 0; tx < kTilesX; ++tx)
    for (int ty = 0; ty < kTilesY; ++ty)
      for (int i = 0; i < h.tile_cells; ++i)  // a diagonal of cells in each tile
        b.add({(tx * h.tile_cells + i + 0.5) * h.resolution_m, (ty * h.tile_cells + i + 0.5) * h.resolution_m},
              tx * 10 + ty + i);
  ASSERT_EQ(b.tile_count(), size_t(kTilesX * kTilesY));
  b.save(dir());

  IntensityMap map(dir(), kMaxCached);
  size_t most_cached = 0, cells = 0;
  for (int gy = 0; gy < kTilesY * h.tile_cells; ++gy)  // a raster walk, row after row
    for (int gx = 0; gx < kTilesX * h.tile_cells; ++gx) {
      const Eigen::Vector2d p = cell_centre(h, gx, gy);
      const auto have = map.cell(p), want = b.cell(p);
      most_cached = std::max(most_cached, map.cached_tiles());
      ASSERT_EQ(have.has_value(), want.has_value());
      if (have) {
        ++cells;
        EXPECT_EQ(have->mean, want->mean);
      }
    }
  EXPECT_LE(most_cached, size_t(kMaxCached));
  EXPECT_EQ(most_cached, size_t(kMaxCached));  // the walk did need more than the cache holds
  EXPECT_GE(map.tiles_loaded(), size_t(kTilesX * kTilesY));
  EXPECT_EQ(cells, size_t(kTilesX * kTilesY * h.tile_cells));
}

// ---------------------------------------------------------------------------------------------------
// 6. Bad maps on disk: an InputError naming the file, never a crash

using IntensityMapErrors = IntensityMapTempDir;

// The message of the InputError `f` throws ("" and a failure if it throws nothing or something else).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no error";
  return "";
}

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

TEST_F(IntensityMapErrors, MissingHeader) {
  const std::string msg = input_error([&] { IntensityMap map(dir()); });
  EXPECT_TRUE(Contains(msg, (dir_ / "map.yaml").string()));
  EXPECT_TRUE(Contains(msg, "cannot open"));
}

TEST_F(IntensityMapErrors, UnknownKeyWithLineAndColumn) {
  two_tile_map().save(dir());
  replace_in_file(dir_ / "map.yaml", "version: 1\n", "version: 1\ncolour: blue\n");
  const std::string msg = input_error([&] { IntensityMap map(dir()); });
  EXPECT_TRUE(Contains(msg, "map.yaml:3:1: unknown key 'colour'"));
}

TEST_F(IntensityMapErrors, BadHeaderValues) {
  struct Case {
    std::string from, to, expect;
  };
  const std::vector<Case> cases = {
      {"format: lidarloop-intensity-map", "format: curb-map", "map.yaml:1:9: format is 'curb-map'"},
      {"version: 1", "version: 2", "map.yaml:2:10: unsupported version 2"},
      {"resolution_m: 0.5", "resolution_m: 0", "resolution_m = 0 must be > 0"},
      {"resolution_m: 0.5", "resolution_m: -0.5", "resolution_m = -0.5 must be > 0"},
      {"tile_cells: 16", "tile_cells: 4", "tile_cells = 4 is out of range [8, 4096]"},
      {"tile_cells: 16", "tile_cells: 5000", "tile_cells = 5000 is out of range [8, 4096]"},
      {"tile_size_m: 8", "tile_size_m: 9", "tile_size_m = 9 does not match"},
      {"projection: transverse_mercator", "projection: utm", "projection 'utm' is not supported"},
      {"world_hash:", "world_hashes:", "unknown key 'world_hashes'"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].to);
    two_tile_map().save(dir());
    replace_in_file(dir_ / "map.yaml", cases[i].from, cases[i].to);
    const std::string msg = input_error([&] { IntensityMap map(dir()); });
    EXPECT_TRUE(Contains(msg, "map.yaml:"));
    EXPECT_TRUE(Contains(msg, cases[i].expect));
  }
  // A required key that is absent, and a tile listed twice.
  two_tile_map().save(dir());
  std::string text = read_bytes(dir_ / "map.yaml");
  const size_t line = text.find("world_hash:");
  text.erase(line, text.find('\n', line) + 1 - line);
  write_bytes(dir_ / "map.yaml", text);
  EXPECT_TRUE(Contains(input_error([&] { IntensityMap map(dir()); }), "missing key 'world_hash'"));
  two_tile_map().save(dir());
  replace_in_file(dir_ / "map.yaml", "  - [1, 0]", "  - [1, 0]\n  - [0, 0]");
  EXPECT_TRUE(Contains(input_error([&] { IntensityMap map(dir()); }), "tile (0, 0) is listed twice"));
}

TEST_F(IntensityMapErrors, MissingTileFile) {
  two_tile_map().save(dir());
  fs::remove(tile_path(0, 0));
  IntensityMap map(dir());  // lazily: the header alone is fine
  EXPECT_TRUE(map.cell({kSmallTileSize + 0.1, 2.0}).has_value());
  const std::string msg = input_error([&] { map.cell({0.1, 1.0}); });
  EXPECT_TRUE(Contains(msg, tile_path(0, 0).string()));
  EXPECT_TRUE(Contains(msg, "missing"));
  // Still an error on a second look, and the map keeps working elsewhere.
  EXPECT_TRUE(Contains(input_error([&] { map.cell({0.1, 1.0}); }), "missing"));
  EXPECT_TRUE(map.cell({kSmallTileSize + 0.1, 2.0}).has_value());
}

TEST_F(IntensityMapErrors, TruncatedTile) {
  two_tile_map().save(dir());
  const std::string bytes = read_bytes(tile_path(0, 0));
  for (size_t keep : {bytes.size() - 1, bytes.size() / 2, size_t(7), size_t(0)}) {
    SCOPED_TRACE(keep);
    write_bytes(tile_path(0, 0), bytes.substr(0, keep));
    IntensityMap map(dir());
    const std::string msg = input_error([&] { map.cell({0.1, 1.0}); });
    EXPECT_TRUE(Contains(msg, tile_path(0, 0).string()));
    EXPECT_TRUE(Contains(msg, "truncated"));
  }
  write_bytes(tile_path(0, 0), bytes + "x");
  IntensityMap map(dir());
  EXPECT_TRUE(Contains(input_error([&] { map.cell({0.1, 1.0}); }), "unexpected bytes"));
}

TEST_F(IntensityMapErrors, FlippedByteFailsTheChecksum) {
  two_tile_map().save(dir());
  const std::string original = read_bytes(tile_path(0, 0));
  // One bit in the cells, one in the header's tile index, one in the checksum itself.
  for (size_t at : {original.size() / 2, size_t(9), original.size() - 1}) {
    SCOPED_TRACE(at);
    std::string bytes = original;
    bytes[at] = char(bytes[at] ^ 0x10);
    write_bytes(tile_path(0, 0), bytes);
    IntensityMap map(dir());
    const std::string msg = input_error([&] { map.cell({0.1, 1.0}); });
    EXPECT_TRUE(Contains(msg, tile_path(0, 0).string()));
    EXPECT_TRUE(Contains(msg, "checksum mismatch"));
  }
}

TEST_F(IntensityMapErrors, BadMagicAndVersion) {
  two_tile_map().save(dir());
  const std::string original = read_bytes(tile_path(0, 0));
  std::string bytes = original;
  bytes[0] = 'X';
  write_bytes(tile_path(0, 0), bytes);
  EXPECT_TRUE(Contains(input_error([&] { IntensityMap(dir()).cell({0.1, 1.0}); }), "bad magic"));
  bytes = original;
  bytes[4] = 2;
  write_bytes(tile_path(0, 0), bytes);
  EXPECT_TRUE(Contains(input_error([&] { IntensityMap(dir()).cell({0.1, 1.0}); }), "unsupported tile version 2"));
}

TEST_F(IntensityMapErrors, TileRenamedToAnotherIndex) {
  two_tile_map().save(dir());
  fs::copy_file(tile_path(0, 0), tile_path(1, 0), fs::copy_options::overwrite_existing);
  IntensityMap map(dir());
  const std::string msg = input_error([&] { map.cell({kSmallTileSize + 0.1, 2.0}); });
  EXPECT_TRUE(Contains(msg, tile_path(1, 0).string()));
  EXPECT_TRUE(Contains(msg, "holds tile (0, 0) but its name says (1, 0)"));
}

TEST_F(IntensityMapErrors, TileCellsDifferFromHeader) {
  two_tile_map().save(dir());
  replace_in_file(dir_ / "map.yaml", "tile_cells: 16", "tile_cells: 32");
  replace_in_file(dir_ / "map.yaml", "tile_size_m: 8", "tile_size_m: 16");
  IntensityMap map(dir());
  const std::string msg = input_error([&] { map.cell({0.1, 1.0}); });
  EXPECT_TRUE(Contains(msg, tile_path(0, 0).string()));
  EXPECT_TRUE(Contains(msg, "tile_cells = 16 but map.yaml says 32"));
}

}  // namespace
}  // namespace lidarloop
