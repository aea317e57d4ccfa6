#include "tools/localizer_loop.hpp"

#include <chrono>
#include <cmath>

namespace lidarloop {
namespace {

using Clock = std::chrono::steady_clock;

class LoopSink : public StreamSink {
 public:
  LoopSink(HdMap& map, const std::vector<LocalizerParams>& methods, StreamSink* also,
           const std::function<void(const LocalizerEstimate&)>& on_estimate, LoopResult& result)
      : also_(also), on_estimate_(on_estimate), result_(result) {
    for (const auto& p : methods) {
      localizers_.push_back(std::make_unique<Localizer>(map, p));
      result_.methods.push_back({method_name(p.method), {}, {}});
    }
  }

  const Localizer& primary() const { return *localizers_.front(); }

  void on_truth(const TruthSample& t) override {
    result_.truth.push_back(t);
    if (also_) also_->on_truth(t);
  }
  void on_can(const CanFrame& f) override {
    timed([&] {
      for (auto& l : localizers_) l->on_can(f);
    });
    if (also_) also_->on_can(f);
  }
  void on_gps(const GpsFix& f) override {
    timed([&] {
      for (auto& l : localizers_) l->on_gps(f);
    });
    if (also_) also_->on_gps(f);
  }
  void on_rtk(const GpsFix& f) override {
    if (also_) also_->on_rtk(f);
  }
  void on_scan(const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose) override {
    if (also_) also_->on_scan(cloud, sensor_pose);
    ++result_.scans;
    for (size_t i = 0; i < localizers_.size(); ++i) {
      LocalizerEstimate e;
      timed([&] { e = localizers_[i]->on_scan(cloud); });
      MethodTrace& trace = result_.methods[i];
      // The latest truth sample is at most one truth period from the estimate: close enough to pick
      // the worst frame (the scorer interpolates properly).
      if (!result_.truth.empty() && !(e.health & kNotInitialized)) {
        const Pose2d& truth = result_.truth.back().pose;
        const double error = std::hypot(e.pose.x - truth.x, e.pose.y - truth.y);
        if (error > trace.worst.error_m) {
          trace.worst = {error, cloud, sensor_pose, localizers_[i]->last_features(), truth, e.pose};
        }
      }
      if (i == 0 && on_estimate_) on_estimate_(e);
      trace.estimates.push_back(std::move(e));
    }
  }
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override {
    if (also_) also_->on_actors(stamp_ns, actors);
  }

 private:
  template <class F>
  void timed(F&& f) {
    const auto t0 = Clock::now();
    f();
    result_.localizer_wall_s += std::chrono::duration<double>(Clock::now() - t0).count();
  }

  std::vector<std::unique_ptr<Localizer>> localizers_;
  StreamSink* also_;
  std::function<void(const LocalizerEstimate&)> on_estimate_;
  LoopResult& result_;
};

}  // namespace

LoopResult run_localizer_loop(Simulation& sim, HdMap& map, const std::vector<LocalizerParams>& methods,
                              bool closed_loop, StreamSink* also, const std::function<void(double)>& progress,
                              const std::function<void(const LocalizerEstimate&)>& on_estimate) {
  LoopResult result;
  if (methods.empty()) return result;
  LoopSink sink(map, methods, also, on_estimate, result);
  if (closed_loop) {
    sim.set_pose_source([&sink](int64_t, const Pose2d& truth) { return sink.primary().pose().value_or(truth); });
  }
  const auto t0 = Clock::now();
  sim.run(sink, progress);
  result.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (closed_loop) sim.set_pose_source({});
  return result;
}

}  // namespace lidarloop
