// Writes the seed corpora that cannot be taken from the repository as they are: small logs recorded by
// the project's own recorder (every topic type a run writes, chunked and compressed as `run --record`
// writes them, uncompressed, unchunked as the exec: stream, and cut short as a killed run leaves them),
// the small map's files, each behind the byte that makes the map target replace it, and HDL-32E data
// packets alone and in a VelodyneScan message.
//   make_fuzz_seeds OUT_DIR   ->  OUT_DIR/mcap/*.mcap, OUT_DIR/hd_map/*, OUT_DIR/hdl32e_packet/*
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "fuzz/small_map.hpp"
#include "localizer/map_files.hpp"
#include "logs/hdl32e_packets.hpp"
#include "logs/mcap_recorder.hpp"

namespace {
using namespace lidarloop;
namespace fs = std::filesystem;

constexpr int kScans = 3;
constexpr int kPointsPerScan = 24;
constexpr int64_t kScanPeriodNs = 100'000'000;  // 10 Hz, as the HDL-32E's default rotation
constexpr int64_t kCyclePeriodNs = 46'080;      // the HDL-32E's firing cycle: one block
constexpr int kSeedBlocks = 2 * kHdl32eBlocksPerPacket;

// Blocks of a scan's first two packets: the azimuth stepping on, returns on some channels, none on others.
Hdl32eRotation seed_rotation(int64_t start_ns) {
  Hdl32eRotation rotation{start_ns, kCyclePeriodNs, {}};
  for (int b = 0; b < kSeedBlocks; ++b) {
    Hdl32eBlock block;
    block.azimuth = uint16_t(18000 + 17 * b);
    for (int c = 0; c < kHdl32eChannels; ++c)
      if ((b + c) % 5 != 0) block.distance[c] = uint16_t(500 + 97 * c), block.intensity[c] = uint8_t(3 * c + b);
    rotation.blocks.push_back(block);
  }
  return rotation;
}

void record_log(const std::string& path, McapWriterOptions options) {
  McapRecorder log(path, Eigen::Isometry3d(Eigen::Translation3d(1.2, 0, 1.9)), Eigen::Vector3d(0.9, 0, 1.5), options);
  log.add_attachment("scenario.yaml", "application/yaml", std::string_view("world: campus\nduration_s: 0.3\n"));
  log.add_metadata("lidarloop.run", {{"seed", "1"}, {"method", "proposed"}});
  for (int i = 0; i < kScans; ++i) {
    const int64_t t = i * kScanPeriodNs;
    TruthSample truth;
    truth.stamp_ns = t;
    truth.pose = Pose2d{1.0 * i, 0.5, 0.01 * i};
    truth.speed = 10;
    log.write_truth(truth);
    log.write_can({t, {10.0, 10.1, 9.9, 10.0}, 0.02});
    GpsFix fix;
    fix.stamp_ns = t;
    fix.status = GpsStatus::fix;
    fix.lat_deg = 31.2856, fix.lon_deg = 121.2147, fix.alt_m = 4;
    fix.position_covariance = {4, 0, 0, 0, 4, 0, 0, 0, 9};
    log.write_gps(fix);
    PointCloud cloud;
    cloud.stamp_ns = t;
    for (int k = 0; k < kPointsPerScan; ++k)
      cloud.points.push_back({float(k), float(-k) * 0.5f, -1.9f, uint8_t(k * 7), uint16_t(k % 32), uint32_t(k * 1152)});
    log.write_scan(cloud);
    log.write_velodyne_scan(seed_rotation(t), t);
    log.write_actors(t, {ros2::ActorState{"bus0", "bus", Pose2d{5.0 + i, 3.5, 0}}});
    // The last scan lost, so the seed holds both an infinite and a finite protection bound.
    LocalizerStatus status;
    status.stamp_ns = t;
    status.lost = i + 1 == kScans;
    status.level = status.lost ? ros2::kDiagnosticError : ros2::kDiagnosticOk;
    status.health = status.lost ? "lost" : "ok";
    if (!status.lost) status.protection_lateral_m = status.protection_longitudinal_m = 0.25;
    log.write_estimate(status, Pose2d{1.0 * i + 0.02, 0.49, 0.01 * i}, Eigen::Matrix3d::Identity() * 0.01);
  }
  log.close();
}

void write_cut(const fs::path& from, const fs::path& to, double fraction) {
  const std::string bytes = read_file_bytes(from, "seed log");
  std::ofstream(to, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() * fraction));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_fuzz_seeds OUT_DIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  fs::create_directories(out / "mcap");
  McapWriterOptions chunked;
  chunked.chunk_duration_ns = kScanPeriodNs;  // a chunk per scan: seeds with several chunks
  record_log(out / "mcap" / "zstd_chunks.mcap", chunked);
  McapWriterOptions plain = chunked;
  plain.compress = false;
  record_log(out / "mcap" / "plain_chunks.mcap", plain);
  McapWriterOptions stream = plain;
  stream.chunked = false;
  record_log(out / "mcap" / "unchunked.mcap", stream);
  write_cut(out / "mcap" / "zstd_chunks.mcap", out / "mcap" / "killed.mcap", 0.7);

  const fs::path map = out / "hd_map_folder";
  fs::remove_all(map);
  fuzz::write_small_map(map.string());
  fs::create_directories(out / "hd_map");
  const auto& files = fuzz::small_map_files();
  for (size_t i = 0; i < files.size(); ++i) {
    std::ofstream seed(out / "hd_map" / std::to_string(i), std::ios::binary);
    seed << char(i) << read_file_bytes(map / files[i], files[i]);
  }
  fs::create_directories(out / "hdl32e_packet");
  ros2::VelodyneScan scan{0, "lidar", hdl32e_data_packets(seed_rotation(0))};
  for (size_t i = 0; i < scan.packets.size(); ++i)
    std::ofstream(out / "hdl32e_packet" / ("packet" + std::to_string(i)), std::ios::binary)
        .write(reinterpret_cast<const char*>(scan.packets[i].data.data()),
               std::streamsize(scan.packets[i].data.size()));
  const ros2::Bytes cdr = ros2::encode_velodyne_scan(scan);
  std::ofstream(out / "hdl32e_packet" / "velodyne_scan.cdr", std::ios::binary)
      .write(reinterpret_cast<const char*>(cdr.data()), std::streamsize(cdr.size()));
  return 0;
}
