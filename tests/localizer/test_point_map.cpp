// The point-cloud layer of the HD map: voxel centroids, tiles written and read back to the same
// points, queries around a position, and bad files (truncated, corrupt, missing) as InputErrors that
// name the file.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "localizer/point_map.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

class PointMapFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = (fs::path(::testing::TempDir()) / ("lidarloop_points_" + std::string(info->name()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A layer of two tiles: points on a 0.25 m grid either side of x = 64 m (the first tile border).
  PointMapHeader write_layer() {
    PointMapHeader h;
    h.world = "test";
    h.world_hash = "abc";
    PointMapBuilder b(h);
    for (double x = 50; x < 80; x += 0.25)
      for (double y = 1; y < 9; y += 0.25) b.add({x, y, 0.1 * x});
    PointMapWriter w(dir_);
    for (const auto& key : b.header().tiles) written_[key] = b.take_tile(key), w.write_tile(key, written_[key]);
    w.finish(b.header());
    return b.header();
  }

  std::string dir_;
  std::map<std::pair<int, int>, std::vector<Eigen::Vector3f>> written_;
};

TEST(PointMapBuilder, OnePointPerVoxelAtTheCentroid) {
  PointMapBuilder b(PointMapHeader{});
  b.add({0.1, 0.1, 0.1});
  b.add({0.3, 0.3, 0.3});  // same 0.4 m voxel
  b.add({0.5, 0.1, 0.1});  // the next along x
  b.add({std::nan(""), 0, 0});
  const std::vector<Eigen::Vector3f> tile = b.take_tile({0, 0});
  ASSERT_EQ(tile.size(), 2u);
  EXPECT_NEAR(tile[0].x(), 0.2, 1e-6);
  EXPECT_NEAR(tile[0].z(), 0.2, 1e-6);
  EXPECT_NEAR(tile[1].x(), 0.5, 1e-6);
  EXPECT_THROW(b.add({0.1, 0.1, 0.1}), std::logic_error);  // the tile was handed over
}

TEST(PointMapBuilder, MergingPartsGivesTheWholesCentroids) {
  PointMapBuilder whole(PointMapHeader{}), a(PointMapHeader{}), b(PointMapHeader{});
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d p(0.013 * i, 0.007 * i, 0.003 * i);
    whole.add(p);
    (i % 2 ? a : b).add(p);
  }
  PointMapBuilder merged(PointMapHeader{});
  merged.merge(a);
  merged.merge(b);
  const auto x = whole.take_tile({0, 0}), y = merged.take_tile({0, 0});
  ASSERT_EQ(x.size(), y.size());
  for (size_t i = 0; i < x.size(); ++i) EXPECT_TRUE(x[i].isApprox(y[i], 1e-5f));
}

TEST_F(PointMapFiles, TilesRoundTripToTheSamePoints) {
  const PointMapHeader h = write_layer();
  ASSERT_EQ(h.tiles.size(), 2u);
  const PointMapHeader read = read_point_map_header(dir_);
  EXPECT_EQ(read.world, "test");
  EXPECT_EQ(read.tiles, h.tiles);
  EXPECT_EQ(read.voxel_m, h.voxel_m);
  for (const auto& [key, points] : written_) {
    const std::vector<Eigen::Vector3f> back = read_point_tile(point_tile_file(dir_, key), key);
    ASSERT_EQ(back.size(), points.size());
    for (size_t i = 0; i < back.size(); ++i) EXPECT_TRUE(back[i] == points[i]);  // bit for bit
  }
  PointMap map(dir_, 1);  // one tile cached: the query reads both, in turn
  const std::vector<Eigen::Vector3d> near = map.points_near({64, 5}, 3.0);
  EXPECT_FALSE(near.empty());
  for (const Eigen::Vector3d& p : near) EXPECT_LE(std::hypot(p.x() - 64, p.y() - 5), 3.0);
  EXPECT_EQ(map.tiles_loaded(), 2u);
  EXPECT_TRUE(map.points_near({500, 500}, 10).empty());  // off the map
}

TEST_F(PointMapFiles, ATruncatedOrCorruptTileIsAnInputErrorNamingIt) {
  const PointMapHeader h = write_layer();
  const auto key = h.tiles.front();
  const std::string file = point_tile_file(dir_, key);
  const auto size = fs::file_size(file);
  auto expect_error = [&](const std::string& what) {
    try {
      PointMap(dir_).points_near({60, 5}, 5);
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  fs::resize_file(file, size - 7);
  expect_error("truncated");
  fs::resize_file(file, 10);
  expect_error("truncated");
  write_layer();
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(size / 2));
    f.put('\x5a');
  }
  expect_error("checksum");
  fs::remove(file);
  expect_error("missing");
  std::ofstream(dir_ + "/points.yaml") << "format: lidarloop-point-map\nversion: 9\n";
  EXPECT_THROW(read_point_map_header(dir_), InputError);
}

}  // namespace
}  // namespace lidarloop
