// A log's scans whichever way it holds them (logs/scan_messages.hpp): a log with clouds and packets
// gives each scan once, from its clouds; a packets-only log gives the clouds a driver decodes.
#include <unistd.h>
#include <filesystem>

#include <gtest/gtest.h>

#include "logs/mcap_recorder.hpp"
#include "logs/scan_messages.hpp"
#include "mcap_fixture.hpp"

namespace lidarloop {
namespace {

constexpr int kScans = 3;

Hdl32eCalibration calibration() {
  Hdl32eCalibration c;
  for (int k = 0; k < kHdl32eChannels; ++k) {
    c.ring[size_t(k)] = uint16_t(k);
    c.cos_elevation[size_t(k)] = std::cos(0.01 * k);
    c.sin_elevation[size_t(k)] = std::sin(0.01 * k);
  }
  c.firing_period_ns = 1152;
  c.cycle_period_ns = 46080;
  return c;
}

Hdl32eRotation rotation(int scan) {
  Hdl32eRotation r{int64_t(scan) * 100'000'000, 46080, std::vector<Hdl32eBlock>(40)};
  for (size_t k = 0; k < r.blocks.size(); ++k) {
    r.blocks[k].azimuth = uint16_t(90 * k);
    r.blocks[k].distance[(k + size_t(scan)) % 32] = uint16_t(1000 + 10 * k);
    r.blocks[k].intensity[(k + size_t(scan)) % 32] = uint8_t(scan);
  }
  return r;
}

// Records kScans scans as clouds (`clouds`) and/or packets, stamped on the host 1 ms after the sensor.
std::string record(const std::string& name, bool clouds, bool packets) {
  const auto dir = std::filesystem::temp_directory_path() / ("lidarloop_test_scans_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  McapRecorder log(path, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero());
  for (int i = 0; i < kScans; ++i) {
    const Hdl32eRotation r = rotation(i);
    const int64_t stamp = r.start_ns + 1'000'000;
    if (clouds) log.write_scan(hdl32e_cloud(calibration(), stamp, r.blocks));
    if (packets) log.write_velodyne_scan(r, stamp);
  }
  log.close();
  return path;
}

std::vector<PointCloud> scans_of(const std::string& path, const std::string& topic = "") {
  McapReader reader(path);
  std::vector<PointCloud> scans;
  for (McapMessage m; reader.next(m);)
    if (auto scan = scan_message(reader, m, calibration(), topic)) scans.push_back(*scan);
  return scans;
}

void expect_same(const PointCloud& a, const PointCloud& b) {
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t k = 0; k < a.points.size(); ++k) EXPECT_TRUE(test::same_point(a.points[k], b.points[k])) << "point " << k;
}

TEST(ScanMessages, APacketsOnlyLogGivesTheCloudsADriverDecodes) {
  const std::vector<PointCloud> scans = scans_of(record("packets.mcap", false, true));
  ASSERT_EQ(scans.size(), size_t(kScans));
  for (int i = 0; i < kScans; ++i) {
    const Hdl32eRotation r = rotation(i);
    expect_same(scans[size_t(i)], hdl32e_cloud(calibration(), r.start_ns + 1'000'000, r.blocks));
    EXPECT_EQ(scans[size_t(i)].points.size(), 40u);
  }
}

TEST(ScanMessages, ALogWithCloudsAndPacketsGivesEachScanOnce) {
  const std::string both = record("both.mcap", true, true);
  const std::vector<PointCloud> scans = scans_of(both);
  ASSERT_EQ(scans.size(), size_t(kScans));
  // Asked for by topic, the packets decode into the same clouds.
  const std::vector<PointCloud> decoded = scans_of(both, "/velodyne_packets");
  ASSERT_EQ(decoded.size(), size_t(kScans));
  for (int i = 0; i < kScans; ++i) expect_same(scans[size_t(i)], decoded[size_t(i)]);
}

}  // namespace
}  // namespace lidarloop
