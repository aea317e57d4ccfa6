#pragma once
// `lidarloop simulate` output: each stream as a CSV file (one header line, SI units, times in ns),
// every Nth scan as PLY, and the paths driven, for a top-view picture.
#include <fstream>
#include <string>

#include "sim/simulation.hpp"

namespace lidarloop {

class CsvStreams : public StreamSink {
 public:
  // Writes into `dir` (created if needed); scan_every = 0 writes no scans.
  CsvStreams(const std::string& dir, const LocalFrame& frame, int scan_every);

  void on_truth(const TruthSample& s) override;
  void on_can(const CanFrame& f) override;
  void on_gps(const GpsFix& f) override;
  void on_rtk(const GpsFix& f) override;
  void on_scan(const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose) override;
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override;

  // Flushes and closes the files; InputError naming a file that could not be written (a full disk).
  // A write that fails during the run throws at the next sample of its stream.
  void finish();

  const Polyline2d& ego_path() const { return ego_path_; }
  const std::map<std::string, Polyline2d>& actor_paths() const { return actor_paths_; }
  size_t scans() const { return scans_; }
  double cross_track_rms() const;

 private:
  std::ofstream open(const std::string& name, const std::string& header);
  void check(const std::ofstream& out, const char* name) const;
  void write_fix(std::ofstream& out, const GpsFix& f);

  std::string dir_;
  LocalFrame frame_;
  int scan_every_;
  std::ofstream truth_, can_, gps_, rtk_, actors_;
  Polyline2d ego_path_;
  std::map<std::string, Polyline2d> actor_paths_;
  size_t scans_ = 0;
  double cross_track_sq_ = 0;
  size_t truth_count_ = 0;
};

}  // namespace lidarloop
