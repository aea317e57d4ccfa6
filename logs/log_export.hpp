#pragma once
// `lidarloop export`: a log's trajectories and scans in the formats other tools read.
//   TUM    one line "t x y z qx qy qz qw" per pose (t in seconds), for evo;
//   PCD    one binary PCD v0.7 per scan (x y z intensity ring time), with timestamps.txt;
//   KITTI  the raw-data layout: velodyne_points/data/NNNNNNNNNN.bin (float32 x y z reflectance 0-1)
//          with timestamps(_start|_end).txt, oxts/data/NNNNNNNNNN.txt from the RTK (else GPS) fixes
//          with oxts/timestamps.txt and dataformat.txt, and calib_imu_to_velo.txt from /tf_static;
//   PCAP   below.
// Every export reads the whole log through McapReader, so a corrupt log stops it with an InputError.
#include <cstddef>
#include <string>

#include "common/hdl32e_driver.hpp"

namespace lidarloop {

struct ExportResult {
  std::string topic;  // what was exported
  size_t count = 0;   // poses or scans
};

// `topic`: a nav_msgs/msg/Odometry topic; empty picks the localizer's estimate if the log has one,
// else the ground truth.
ExportResult export_tum(const std::string& log, const std::string& file, const std::string& topic = "");
// PCD and KITTI: the scans of logs/scan_messages.hpp, `calibration` decoding a packets-only log's
// packets; `topic` as there (empty: the log's scans).
ExportResult export_pcd(const std::string& log, const std::string& dir, const Hdl32eCalibration& calibration,
                        const std::string& topic = "");
ExportResult export_kitti(const std::string& log, const std::string& dir, const Hdl32eCalibration& calibration,
                          const std::string& topic = "");
// PCAP   the HDL-32E's UDP traffic as a capture (logs/pcap_file.hpp) VeloView or the ROS driver replay:
//        every data packet of a velodyne_msgs/msg/VelodyneScan topic (default /velodyne_packets, logged
//        by `--record FILE --packets`) to port 2368, and a position packet with a $GPRMC from the GPS
//        fix (/gps/fix) to port 8308 at every whole second; capture time = packet stamp.
//        count = data packets.
ExportResult export_pcap(const std::string& log, const std::string& file, const std::string& topic = "");

// "YYYY-MM-DD HH:MM:SS.nnnnnnnnn", UTC, counting from the Unix epoch (KITTI's timestamp format).
std::string kitti_timestamp(int64_t ns);

}  // namespace lidarloop
