// lidarloop info / recover / export / odometry: look into an MCAP log, repair a damaged one, convert one,
// measure its CAN odometry's drift.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "localizer/localizer_params.hpp"
#include "logs/log_export.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/mcap/mcap_recover.hpp"
#include "loop/localizer_setup.hpp"
#include "loop/odometry_drift.hpp"
#include "loop/recorded_log.hpp"
#include "tools/commands.hpp"

namespace lidarloop {

namespace {

std::string seconds(uint64_t ns) {
  char text[48];
  std::snprintf(text, sizeof text, "%" PRIu64 ".%09" PRIu64, ns / 1'000'000'000, ns % 1'000'000'000);
  return text;
}

std::string size_text(uint64_t bytes) {
  char text[32];
  if (bytes < (1u << 20))
    std::snprintf(text, sizeof text, "%.1f KiB", double(bytes) / 1024);
  else
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / (1 << 20));
  return text;
}

int run_info(const Args& args) {
  const std::string path = args.positional().at(0);
  // The summary first: a file without a valid footer is reported at once, with the way out.
  const std::optional<McapSummary> summary = read_mcap_summary(path);

  // Then, unless --quick, every record: CRCs checked, counts taken from the messages themselves.
  std::map<uint16_t, uint64_t> counts;
  std::map<uint16_t, mcap::Channel> channels;
  std::map<uint16_t, mcap::Schema> schemas;
  std::vector<mcap::Metadata> metadata;
  std::vector<mcap::Attachment> attachments;
  uint64_t messages = 0, start = 0, end = 0, chunks = 0;
  mcap::Header header;
  const bool verify = !args.flag("quick") || !summary || !summary->statistics;
  if (verify) {
    McapReader reader(path);
    header = reader.header();
    for (McapMessage m; reader.next(m);) {
      ++counts[m.channel->id];
      start = messages == 0 ? m.log_time : std::min(start, m.log_time);
      end = messages == 0 ? m.log_time : std::max(end, m.log_time);
      ++messages;
    }
    channels = reader.channels();
    schemas = reader.schemas();
    metadata = reader.metadata();
    attachments = reader.attachments();
    chunks = reader.chunks();
    if (summary && summary->statistics) {
      const auto& s = *summary->statistics;
      if (s.message_count != messages || (!s.channel_message_counts.empty() && [&] {
            for (const auto& [id, n] : s.channel_message_counts)
              if ((counts.count(id) ? counts[id] : 0) != n) return true;
            return false;
          }()))
        throw InputError(path + ": the summary's message counts disagree with the messages in the file");
    }
  } else {
    McapReader reader(path);  // the header only
    header = reader.header();
    const auto& s = *summary->statistics;
    counts = s.channel_message_counts;
    messages = s.message_count;
    start = s.message_start_time;
    end = s.message_end_time;
    chunks = s.chunk_count;
    channels = summary->channels;
    schemas = summary->schemas;
  }

  uint64_t compressed = 0, uncompressed = 0;
  std::map<std::string, uint64_t> compression;
  if (summary)
    for (const auto& c : summary->chunk_indexes) {
      compressed += c.compressed_size;
      uncompressed += c.uncompressed_size;
      ++compression[c.compression.empty() ? "none" : c.compression];
    }

  std::cout << "file:         " << path << "\n"
            << "library:      " << header.library << "\n"
            << "profile:      " << header.profile << "\n"
            << "messages:     " << messages << "\n"
            << "duration:     " << seconds(end >= start ? end - start : 0) << " s\n"
            << "start:        " << seconds(start) << " s\n"
            << "end:          " << seconds(end) << " s\n"
            << "chunks:       " << chunks;
  for (const auto& [name, n] : compression) std::cout << "  [" << name << ": " << n << "]";
  if (uncompressed > 0) {
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.2f", double(uncompressed) / double(std::max<uint64_t>(compressed, 1)));
    std::cout << "  " << size_text(uncompressed) << " -> " << size_text(compressed) << " (ratio " << ratio << ")";
  }
  std::cout << "\nchannels:\n";
  size_t width = 0, id_width = 1;
  for (const auto& [id, c] : channels) {
    width = std::max(width, c.topic.size());
    id_width = std::max(id_width, std::to_string(id).size());
  }
  const double span_s = end > start ? double(end - start) * 1e-9 : 0.0;
  for (const auto& [id, c] : channels) {
    const uint64_t n = counts.count(id) ? counts.at(id) : 0;
    std::string topic = c.topic;
    topic.resize(width, ' ');
    char rate[32] = "            ";  // as wide as " %8.2f Hz"
    if (n > 1 && span_s > 0) std::snprintf(rate, sizeof rate, " %8.2f Hz", double(n) / span_s);
    const auto schema = schemas.find(c.schema_id);
    std::printf("  (%*u) %s %8" PRIu64 " msgs%s : %s [%s/%s]\n", int(id_width), unsigned(id), topic.c_str(), n, rate,
                schema == schemas.end() ? "(no schema)" : schema->second.name.c_str(),
                schema == schemas.end() ? "-" : schema->second.encoding.c_str(), c.message_encoding.c_str());
  }
  std::fflush(stdout);
  if (verify) {
    std::cout << "attachments:  " << attachments.size() << "\n";
    for (const auto& a : attachments)
      std::cout << "  " << a.name << " (" << a.media_type << ", " << a.data.size() << " bytes)\n";
    std::cout << "metadata:     " << metadata.size() << "\n";
    for (const auto& m : metadata) {
      std::cout << "  " << m.name << ":";
      for (const auto& [k, v] : m.metadata) std::cout << " " << k << "=" << v;
      std::cout << "\n";
    }
    std::cout << "integrity:    ok (chunk, data-section and summary CRCs checked)\n";
  } else {
    std::cout << "attachments:  " << summary->attachment_indexes.size() << "\n"
              << "metadata:     " << summary->metadata_indexes.size() << "\n"
              << "integrity:    not checked (--quick)\n";
  }
  return 0;
}

int run_recover(const Args& args) {
  const std::string in = args.positional().at(0), out = args.positional().at(1);
  const McapRecoverReport r = recover_mcap(in, out);
  std::cout << "recovered    " << r.messages << " messages in " << r.chunks << " chunks, " << r.attachments
            << " attachments, " << r.metadata << " metadata records\n"
            << "input        " << in << " (" << r.input_bytes
            << " bytes): " << (r.complete ? "complete" : "incomplete (no Data End record)") << "\n";
  if (r.skipped_chunks || r.skipped_bytes || r.orphan_messages)
    std::cout << "lost         " << r.skipped_chunks << " corrupt chunks, " << r.skipped_bytes << " unreadable bytes, "
              << r.orphan_messages << " messages on undefined channels\n";
  for (const auto& p : r.problems) std::cout << "  " << p << "\n";
  std::cout << "output       " << out << "\n";
  return 0;
}

int run_export(const Args& args) {
  const std::string log = args.positional().at(0), topic = args.text("topic", "");
  const int chosen = int(args.flag("tum")) + int(args.flag("pcd")) + int(args.flag("kitti")) + int(args.flag("pcap"));
  if (chosen != 1) throw InputError("export: give exactly one of --tum FILE, --pcd DIR, --kitti DIR, --pcap FILE");
  ExportResult r;
  std::string what, where;
  if (auto file = args.value("tum")) {
    r = export_tum(log, *file, topic);
    what = "poses", where = *file;
  } else if (auto dir = args.value("pcd")) {
    r = export_pcd(log, *dir, recorded_calibration(log), topic);
    what = "scans", where = *dir;
  } else if (auto pcap = args.value("pcap")) {
    r = export_pcap(log, *pcap, topic);
    what = "HDL-32E data packets", where = *pcap;
  } else {
    where = *args.value("kitti");
    r = export_kitti(log, where, recorded_calibration(log), topic);
    what = "scans";
  }
  std::cout << "exported     " << r.count << " " << what << " from " << r.topic << " to " << where << "\n";
  return 0;
}

int run_odometry(const Args& args) {
  const std::string log = args.positional().at(0), lengths_text = args.text("lengths", "10,50,200");
  const std::vector<double> lengths = parse_number_list(
      lengths_text, size_t(std::count(lengths_text.begin(), lengths_text.end(), ',')) + 1, "--lengths");
  for (double l : lengths)
    if (!(l > 0)) throw InputError("--lengths: every length must be positive, got " + lengths_text);
  const RecordedLog recorded = read_recorded_log(log);
  if (recorded.can.empty()) throw InputError(log + ": no /vehicle/report messages (CAN) to dead-reckon");
  // What the run's localizer knew of the car and how it integrates Eq. 19.
  const LocalizerParams params = localizer_params_for(recorded.run.scenario);
  const std::vector<OdometryDrift> drift =
      odometry_drift(recorded.truth, recorded.can, params.vehicle, params.max_prediction_step_s, lengths);
  std::printf("odometry   %s: %zu CAN frames dead-reckoned with Eq. 19 against %zu truth samples\n", log.c_str(),
              recorded.can.size(), recorded.truth.size());
  std::printf("%10s %10s %14s %17s %13s   %s\n", "length m", "stretches", "lateral RMS m", "longitudinal RMS m",
              "heading deg", "per sqrt(m): lateral, longitudinal m, heading rad");
  for (const OdometryDrift& d : drift) {
    if (d.stretches == 0) {
      std::printf("%10.1f %10s   (the drive is shorter)\n", d.length_m, "0");
      continue;
    }
    const double root = std::sqrt(d.length_m);
    std::printf("%10.1f %10zu %14.4f %17.4f %13.4f   %.4f, %.4f, %.5f\n", d.length_m, d.stretches, d.lateral_rms_m,
                d.longitudinal_rms_m, d.heading_rms_rad * kDegPerRad, d.lateral_rms_m / root,
                d.longitudinal_rms_m / root, d.heading_rms_rad / root);
  }
  std::printf(
      "filter     the process noise it stands for: position %.4f m/sqrt(m) and %.3f m/sqrt(s), heading %.5f "
      "rad/sqrt(m) and %.4f rad/sqrt(rad) turned (filter: in the localizer's parameters)\n",
      params.filter.position_per_sqrt_m, params.filter.position_per_sqrt_s, params.filter.yaw_per_sqrt_m,
      params.filter.yaw_per_sqrt_rad);
  return 0;
}

}  // namespace

Command odometry_command() {
  return {{"odometry",
           "lidarloop odometry FILE.mcap [--lengths 10,50,200]",
           "Measure how far the CAN odometry of a recorded run drifts from its truth: the wheel speeds and\n"
           "steering dead-reckoned with the localizer's Eq. 19 over every stretch of each length (one a metre),\n"
           "the error at its end across and along the road and in heading, as RMS and per square root of\n"
           "the length, beside the localizer's process noise.",
           {{"lengths", "M,M,...", "stretch lengths in metres (default 10,50,200)"}},
           1,
           1},
          run_odometry};
}

Command info_command() {
  return {{"info",
           "lidarloop info FILE.mcap [--quick]",
           "Show an MCAP log's topics, message types, counts, rates, time range, chunks and compression,\n"
           "attachments and metadata, after checking every CRC in the file.",
           {{"quick", "", "read only the summary section (no integrity check)"}},
           1,
           1},
          run_info};
}

Command recover_command() {
  return {{"recover",
           "lidarloop recover BROKEN.mcap FIXED.mcap",
           "Rebuild a damaged MCAP log (cut off by a crash, truncated, corrupted): every intact chunk's\n"
           "messages, the attachments and metadata go into a new, complete, indexed file.",
           {},
           2,
           2},
          run_recover};
}

Command export_command() {
  return {{"export",
           "lidarloop export FILE.mcap (--tum FILE | --pcd DIR | --kitti DIR | --pcap FILE) [--topic TOPIC]",
           "Convert a log: a trajectory to TUM (for evo), scans to PCD files, scans and RTK fixes to\n"
           "the KITTI raw-data layout, or the sensor's packets to a pcap capture (VeloView, ROS driver).",
           {{"tum", "FILE", "write a nav_msgs/Odometry topic as TUM (default: the estimate, else the truth)"},
            {"pcd", "DIR", "write each scan as a binary PCD file"},
            {"kitti", "DIR", "write the KITTI raw layout (velodyne_points, oxts, calib_imu_to_velo.txt)"},
            {"pcap", "FILE", "write the HDL-32E's UDP packets (log recorded with --packets) as a pcap capture"},
            {"topic", "TOPIC", "the topic to export (default /localizer/odometry or /truth/odometry; /lidar/points)"}},
           1,
           1},
          run_export};
}

}  // namespace lidarloop
