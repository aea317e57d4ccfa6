#include "loop/localizer_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <variant>

#include "common/input_error.hpp"
#include "loop/fault_events.hpp"
#include "loop/localizer_backend.hpp"
#include "scoring/scorer.hpp"

namespace lidarloop {
namespace {

using Clock = std::chrono::steady_clock;

struct ScanMessage {
  PointCloud cloud;
  Eigen::Isometry3d sensor_pose;
};
// What the localizers consume, in the order the simulation emitted it.
using Message = std::variant<TruthSample, CanFrame, GpsFix, ScanMessage>;

// The localizers and what they produced. One thread at a time calls process(); nothing else is shared.
class Localizers {
 public:
  Localizers(HdMap& map, const std::vector<LocalizerParams>& methods, const Scenario& scenario, LoopResult& result)
      : scenario_(scenario), result_(result) {
    for (const auto& p : methods) {
      localizers_.push_back(std::make_unique<LocalizerBackend>(map, p, scenario));
      result_.methods.push_back({localizers_.back()->label(), {}, {}, {}});
    }
  }

  // Returns the first method's estimate for a scan, nothing for the other messages.
  std::optional<LocalizerEstimate> process(const Message& m) {
    const auto t0 = Clock::now();
    std::optional<LocalizerEstimate> primary;
    if (const auto* t = std::get_if<TruthSample>(&m)) {
      if (!latest_truth_) events_ = fault_events(scenario_, t->stamp_ns);
      latest_truth_ = t->pose;
    }
    if (const auto* f = std::get_if<CanFrame>(&m))
      for (auto& l : localizers_) l->on_can(*f);
    if (const auto* f = std::get_if<GpsFix>(&m))
      for (auto& l : localizers_) l->on_gps(*f);
    if (const auto* s = std::get_if<ScanMessage>(&m)) {
      for (size_t i = 0; i < localizers_.size(); ++i) {
        LocalizerEstimate e = localizers_[i]->on_scan(s->cloud);
        MethodTrace& trace = result_.methods[i];
        // The latest truth sample is at most one truth period from the estimate: close enough to pick
        // the worst frame (the scorer interpolates properly), among the frames the scorer rates.
        const int64_t first_ns = trace.estimates.empty() ? e.stamp_ns : trace.estimates.front().stamp_ns;
        if (latest_truth_ && !(e.health & kNotInitialized) && !settling(e.stamp_ns, first_ns, scenario_.pass) &&
            !recovering(e.stamp_ns, scenario_.pass, events_)) {
          const double error = std::hypot(e.pose.x - latest_truth_->x, e.pose.y - latest_truth_->y);
          if (error > trace.worst.error_m)
            trace.worst = {error, s->cloud, s->sensor_pose, localizers_[i]->last_features(), *latest_truth_, e.pose};
        }
        if (i == 0) primary = e;
        trace.estimates.push_back(std::move(e));
      }
    }
    result_.localizer_wall_s += std::chrono::duration<double>(Clock::now() - t0).count();
    return primary;
  }

  // After the drive: external programs are told the stream ended and must exit cleanly. One that
  // does not fails its method (MethodTrace::failure), which keeps what it answered until then.
  void finish() {
    for (size_t i = 0; i < localizers_.size(); ++i) try {
        localizers_[i]->finish();
      } catch (const InputError& e) {
        result_.methods[i].failure = e.what();
      }
  }

 private:
  std::vector<std::unique_ptr<LocalizerBackend>> localizers_;
  const Scenario& scenario_;
  std::vector<FaultEvent> events_;  // from the first truth sample on
  std::optional<Pose2d> latest_truth_;
  LoopResult& result_;
};

// The localizers run on a thread of their own while the simulation computes the next scan, so the two
// cores are both busy. The localizers see the same messages in the same order as in series, so they
// give the same estimates; in closed loop the controller gets them a scan late (see DelayedPose).
// The recorder (`also`) still sees everything in the serial order: scan k, its estimate, the messages
// up to scan k + 1. Messages after scan k are held back until estimate k is out, which the
// simulation waits for at scan k + 1 at the latest.
class PipelinedSink : public StreamSink {
 public:
  PipelinedSink(Localizers& localizers, StreamSink* also,
                const std::function<void(const LocalizerEstimate&)>& on_estimate)
      : localizers_(localizers), also_(also), on_estimate_(on_estimate), worker_([this] { work(); }) {}
  ~PipelinedSink() override { stop(); }

  void on_truth(const TruthSample& t) override {
    push(t);
    hold([this, t] { also_->on_truth(t); });
  }
  void on_can(const CanFrame& f) override {
    push(f);
    hold([this, f] { also_->on_can(f); });
  }
  void on_gps(const GpsFix& f) override {
    push(f);
    hold([this, f] { also_->on_gps(f); });
  }
  void on_rtk(const GpsFix& f) override {
    hold([this, f] { also_->on_rtk(f); });
  }
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& actors) override {
    hold([this, stamp_ns, actors] { also_->on_actors(stamp_ns, actors); });
  }
  void on_curb_visibility(const CurbVisibility& v) override {
    hold([this, v] { also_->on_curb_visibility(v); });
  }
  void on_scan(const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose) override {
    release_previous_scan();
    if (also_) also_->on_scan(cloud, sensor_pose);
    push(ScanMessage{cloud, sensor_pose});
    scan_outstanding_ = true;
  }
  void on_lidar_rotation(const Hdl32eRotation& r, int64_t stamp_ns) override {
    if (also_) also_->on_lidar_rotation(r, stamp_ns);  // the scan's packets, next to the scan
  }

  // Scan k's estimate (k counted from 0) once the localizers have made it, before it is handed out;
  // rethrows what the localizers threw. Only for a scan not yet handed out.
  LocalizerEstimate wait_for(size_t k) {
    std::unique_lock lock(mutex_);
    estimate_ready_.wait(lock, [&] { return estimates_.size() > k - handed_out_ || failure_; });
    if (failure_) std::rethrow_exception(failure_);
    return estimates_[k - handed_out_];
  }

  // Waits for the last scan's estimate, hands out everything held back and stops the worker once it
  // has processed everything; rethrows what the localizers threw. Call after the run.
  void finish() {
    release_previous_scan();
    stop();
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  void stop() {
    if (!worker_.joinable()) return;
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_worker_.notify_one();
    worker_.join();
  }
  void push(Message m) {
    {
      std::lock_guard lock(mutex_);
      queue_.push_back(std::move(m));
    }
    wake_worker_.notify_one();
  }
  void hold(std::function<void()> f) {
    if (!also_) return;
    if (scan_outstanding_)
      held_.push_back(std::move(f));
    else
      f();
  }
  void release_previous_scan() {
    if (!scan_outstanding_) return;
    LocalizerEstimate e;
    {
      std::unique_lock lock(mutex_);
      estimate_ready_.wait(lock, [this] { return !estimates_.empty() || failure_; });
      if (failure_) std::rethrow_exception(failure_);
      e = std::move(estimates_.front());
      estimates_.pop_front();
      ++handed_out_;
    }
    scan_outstanding_ = false;
    if (on_estimate_) on_estimate_(e);
    for (auto& f : held_) f();
    held_.clear();
  }

  void work() {
    for (;;) {
      Message m;
      {
        std::unique_lock lock(mutex_);
        wake_worker_.wait(lock, [this] { return !queue_.empty() || stop_; });
        if (queue_.empty()) return;  // stopped, and everything processed
        m = std::move(queue_.front());
        queue_.pop_front();
      }
      try {
        std::optional<LocalizerEstimate> e = localizers_.process(m);
        if (e) {
          std::lock_guard lock(mutex_);
          estimates_.push_back(std::move(*e));
        }
        if (e) estimate_ready_.notify_one();
      } catch (...) {
        std::lock_guard lock(mutex_);
        failure_ = std::current_exception();
        estimate_ready_.notify_one();
        return;
      }
    }
  }

  Localizers& localizers_;
  StreamSink* also_;
  std::function<void(const LocalizerEstimate&)> on_estimate_;
  bool scan_outstanding_ = false;            // simulation thread only
  size_t handed_out_ = 0;                    // written by the simulation thread only, under the mutex
  std::vector<std::function<void()>> held_;  // simulation thread only
  std::mutex mutex_;                         // guards the four below
  std::condition_variable wake_worker_, estimate_ready_;
  std::deque<Message> queue_;
  std::deque<LocalizerEstimate> estimates_;
  std::exception_ptr failure_;
  bool stop_ = false;
  std::thread worker_;  // last: starts once everything above exists
};

// The controller's pose in closed loop: the newest estimate it has been given (EstimateDelivery says
// when), brought up to the present with CAN odometry (Eq. 19), which is what a real car's controller
// does with a localizer's output (unless the scenario's controller has dead_reckoning off). Until the
// first estimate: ground truth.
class DelayedPose {
 public:
  DelayedPose(const LocalizerParams& params, bool dead_reckoning) : params_(params), dead_reckoning_(dead_reckoning) {}

  void on_can(const CanFrame& f) {
    const CanMotion m = can_motion(f, params_.vehicle);
    if (!std::isfinite(m.speed) || !std::isfinite(m.steer)) return;
    if (!history_.empty() && f.stamp_ns < history_.back().stamp_ns) return;  // stale, as the localizer
    Odometry o = history_.empty() ? Odometry{f.stamp_ns, {}, {}, MotionPredictor(params_.vehicle)}
                                  : advanced(history_.back(), f.stamp_ns);
    o.motion = m;
    history_.push_back(o);
    // Keep what a handed-out estimate can still be referred to.
    const int64_t keep_from = estimate_ ? estimate_->stamp_ns : f.stamp_ns - kKeepWithoutEstimateNs;
    while (history_.size() > 1 && history_[1].stamp_ns <= keep_from) history_.pop_front();
  }
  void on_estimate(const LocalizerEstimate& e) {
    if (!(e.health & kNotInitialized)) estimate_ = Stamped{e.stamp_ns, e.pose};
  }
  Pose2d pose(int64_t t_ns, const Pose2d& truth) const {
    if (!estimate_ || history_.empty()) return truth;
    if (!dead_reckoning_) return estimate_->pose;
    return estimate_->pose.compose(relative(odometry_at(estimate_->stamp_ns), odometry_at(t_ns)));
  }

 private:
  // Before the first estimate, the odometry of this long is kept: a first estimate older than this
  // (a localizer so slow it fell seconds behind) is carried from the oldest kept frame.
  static constexpr int64_t kKeepWithoutEstimateNs = 10'000'000'000;
  struct Stamped {
    int64_t stamp_ns;
    Pose2d pose;
  };
  // Dead reckoning in a frame of its own, as of a CAN frame, with that frame's speed and steering.
  struct Odometry {
    int64_t stamp_ns;
    Pose2d pose;
    CanMotion motion;
    MotionPredictor predictor;
  };
  // `o` driven on to t_ns in the localizer's Euler steps.
  Odometry advanced(Odometry o, int64_t t_ns) const {
    if (t_ns <= o.stamp_ns) return o;
    o.pose =
        o.predictor.advance(o.pose, o.motion.speed, o.motion.steer, t_ns - o.stamp_ns, params_.max_prediction_step_s);
    o.stamp_ns = t_ns;
    return o;
  }
  Pose2d odometry_at(int64_t t_ns) const {
    auto after = std::upper_bound(history_.begin(), history_.end(), t_ns,
                                  [](int64_t t, const Odometry& o) { return t < o.stamp_ns; });
    return advanced(after == history_.begin() ? history_.front() : *std::prev(after), t_ns).pose;
  }

  const LocalizerParams& params_;
  bool dead_reckoning_;
  std::deque<Odometry> history_;
  std::optional<Stamped> estimate_;
};

// When each estimate reaches the controller (LatencyParams), in simulated time: the localizer starts
// on scan k when the scan is complete or when it is done with scan k - 1, whichever is later, takes
// the scan's latency, and the controller gets the estimate then. So a localizer slower than the scan
// period falls behind, as a real one that does not drop scans would. The delivery depends only on the
// simulation's events and the latencies, never on how fast the worker thread is: with a fixed latency
// (one scan period is the pipelined loop's own: estimate k at scan k + 1) a run stays repeatable.
class EstimateDelivery {
 public:
  EstimateDelivery(const LatencyParams& latency, int64_t scan_period_ns, PipelinedSink& sink, DelayedPose& pose)
      : latency_(latency), scan_period_ns_(scan_period_ns), sink_(sink), pose_(pose) {}

  void on_scan(int64_t t_ns) { complete_ns_.push_back(t_ns); }
  void on_handed_out(const LocalizerEstimate& e) { handed_out_.push_back(e); }

  // Gives the controller every estimate due by t_ns; may wait for the localizers to make one.
  void deliver_due(int64_t t_ns) {
    while (next_ < complete_ns_.size()) {
      const int64_t start_ns = std::max(complete_ns_[next_], done_ns_);
      if (t_ns < start_ns) return;
      if (!due_ns_) due_ns_ = start_ns + latency_ns();
      if (t_ns < *due_ns_) return;
      pose_.on_estimate(estimate(next_));
      delays_ms_.push_back(1e-6 * double(*due_ns_ - complete_ns_[next_]));
      done_ns_ = *due_ns_;
      due_ns_.reset();
      ++next_;
      while (first_handed_out_ < next_ && !handed_out_.empty()) {  // the controller has had these
        handed_out_.pop_front();
        ++first_handed_out_;
      }
    }
  }
  // Per delivered estimate: from its scan's completion to the controller, ms.
  const std::vector<double>& delays_ms() const { return delays_ms_; }

 private:
  int64_t latency_ns() {
    switch (latency_.model) {
      case LatencyModel::one_scan:
        return scan_period_ns_;
      case LatencyModel::fixed:
        return std::llround(latency_.fixed_ms * 1e6);
      case LatencyModel::measured:
        return std::llround(estimate(next_).total_ms * 1e6);
      case LatencyModel::automatic:
        break;
    }
    throw std::logic_error("EstimateDelivery: the latency model was not resolved");
  }
  LocalizerEstimate estimate(size_t k) {
    if (k < first_handed_out_ + handed_out_.size()) return handed_out_[k - first_handed_out_];
    return sink_.wait_for(k);
  }

  LatencyParams latency_;
  int64_t scan_period_ns_;
  PipelinedSink& sink_;
  DelayedPose& pose_;
  std::vector<int64_t> complete_ns_;          // per scan: when the simulation completed it
  std::deque<LocalizerEstimate> handed_out_;  // from scan first_handed_out_ on
  size_t first_handed_out_ = 0;
  size_t next_ = 0;                // the next scan whose estimate the controller has not been given
  int64_t done_ns_ = INT64_MIN;    // when the localizer finished the previous scan
  std::optional<int64_t> due_ns_;  // scan next_'s estimate's delivery, once known
  std::vector<double> delays_ms_;
};

// What the simulation thread itself takes from the streams before the localizers' sink: the truth for
// the scorer, the scan count, and the CAN frames the controller's dead reckoning needs.
class SimulationTap : public StreamSink {
 public:
  SimulationTap(StreamSink& next, LoopResult& result, DelayedPose* controller_pose,
                std::function<void()> on_scan_complete)
      : next_(next),
        result_(result),
        controller_pose_(controller_pose),
        on_scan_complete_(std::move(on_scan_complete)) {}
  void on_truth(const TruthSample& t) override {
    result_.truth.push_back(t);
    next_.on_truth(t);
  }
  void on_can(const CanFrame& f) override {
    if (controller_pose_) controller_pose_->on_can(f);
    next_.on_can(f);
  }
  void on_gps(const GpsFix& f) override { next_.on_gps(f); }
  void on_rtk(const GpsFix& f) override { next_.on_rtk(f); }
  void on_actors(int64_t stamp_ns, const std::vector<ActorSample>& a) override { next_.on_actors(stamp_ns, a); }
  void on_scan(const PointCloud& cloud, const Eigen::Isometry3d& sensor_pose) override {
    ++result_.scans;
    if (on_scan_complete_) on_scan_complete_();
    next_.on_scan(cloud, sensor_pose);
  }
  void on_lidar_rotation(const Hdl32eRotation& r, int64_t stamp_ns) override { next_.on_lidar_rotation(r, stamp_ns); }
  void on_curb_visibility(const CurbVisibility& v) override {
    result_.curb_visibility.push_back(v);
    next_.on_curb_visibility(v);
  }

 private:
  StreamSink& next_;
  LoopResult& result_;  // only the fields above: the localizers' thread writes the others
  DelayedPose* controller_pose_;
  std::function<void()> on_scan_complete_;
};

}  // namespace

LatencyParams controller_latency(const LocalizerParams& params) {
  if (params.latency.model != LatencyModel::automatic) return params.latency;
  return {params.external.command.empty() ? LatencyModel::one_scan : LatencyModel::measured, 0};
}

LoopResult run_localizer_loop(Simulation& sim, HdMap& map, const std::vector<LocalizerParams>& methods,
                              bool closed_loop, StreamSink* also, const std::function<void(double)>& progress,
                              const std::function<void(const LocalizerEstimate&)>& on_estimate) {
  LoopResult result;
  if (methods.empty()) return result;
  Localizers localizers(map, methods, sim.scenario(), result);
  std::optional<DelayedPose> controller_pose;
  std::optional<EstimateDelivery> delivery;
  if (closed_loop) controller_pose.emplace(methods.front(), sim.scenario().ego.controller.dead_reckoning);
  const auto handed_out = [&](const LocalizerEstimate& e) {
    if (delivery) delivery->on_handed_out(e);
    if (on_estimate) on_estimate(e);
  };
  const auto t0 = Clock::now();
  {
    PipelinedSink sink(localizers, also, handed_out);
    std::function<void()> on_scan_complete;
    if (closed_loop) {
      delivery.emplace(controller_latency(methods.front()), sim.scenario().lidar.scan_period_ns(), sink,
                       *controller_pose);
      on_scan_complete = [&] { delivery->on_scan(sim.now_ns()); };
      sim.set_pose_source([&](int64_t t_ns, const Pose2d& truth) {
        delivery->deliver_due(t_ns);
        return controller_pose->pose(t_ns, truth);
      });
    }
    SimulationTap tap(sink, result, controller_pose ? &*controller_pose : nullptr, on_scan_complete);
    sim.run(tap, progress);
    sim.set_pose_source({});
    sink.finish();
    if (delivery) result.controller_delays_ms = delivery->delays_ms();
    delivery.reset();  // it refers to the sink
  }
  localizers.finish();
  result.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return result;
}

}  // namespace lidarloop
