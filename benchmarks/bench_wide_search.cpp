// The relocalization searches' cost per call (wide_search.hpp, curb_hypotheses.hpp) with their default
// parameters, against the localizer's budget (p50 8 ms, p99 20 ms a scan, of which a normal scan takes
// 5-10 ms):
//   build/benchmarks/bench_wide_search
// - BM_WideApsStep: WideApsSearch run to the end on one S, one step per iteration of its loop; the
//   counters give the steps a search takes and the slowest step (ms).
// - BM_WideApsOneShot: the whole search in one call, for comparison.
// - BM_CurbHypothesesStep, BM_CurbHypothesesOneShot: the grid of ICP starts on a scan's worth of curbs
//   at a city block, spread over steps and in one call.
// S is Table I's 200 x 200 cells of 0.2 m, usable over a 12 m wide road the length of the grid (the
// corridor's ground), over a map of irregular paint.
#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "localizer/curb_hypotheses.hpp"
#include "localizer/wide_search.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr double kResolution = 0.2;  // the map's cells (Table I scale)
constexpr double kMapHalf = 50.0;    // m: S's 28 m reach, the search's 6 m and more
constexpr double kRoadHalfWidth = 6.0;
constexpr int kSamplesPerCell = 6;                       // points per cell of the map and of S: above n_e = 3
constexpr double kPaint = 35, kAsphalt = 6, kNoise = 2;  // intensity counts
constexpr double kDeg = std::numbers::pi / 180.0;

// Lane lines and random patches of paint.
bool painted(const Eigen::Vector2d& p) {
  if (std::fabs(std::fabs(p.y()) - 3.5) < 0.08) return true;
  if (std::fabs(p.y()) < 0.08 && std::fmod(p.x() + 1000.0, 7.3) < 3.1) return true;
  const double u = std::sin(0.37 * p.x()) * std::cos(0.53 * p.y()) + std::sin(0.11 * p.x() * p.y());
  return u > 1.2;
}

double intensity(const Eigen::Vector2d& p, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, kNoise);
  return (painted(p) ? kPaint : kAsphalt) + noise(rng);
}

// The map, built once per process in a temporary folder.
const std::string& map_dir() {
  static const std::string dir = [] {
    IntensityMapHeader h;
    h.world = "bench_wide_search";
    h.world_hash = "0123456789abcdef";
    h.origin = {31.2856, 121.2147, 4.0};
    h.resolution_m = kResolution;
    IntensityMapBuilder builder(h);
    std::mt19937 rng(1);
    const int side = int(2 * kMapHalf / kResolution);
    for (int r = 0; r < side; ++r)
      for (int c = 0; c < side; ++c)
        for (int k = 0; k < kSamplesPerCell; ++k) {
          const Eigen::Vector2d p(-kMapHalf + (c + 0.5) * kResolution, -kMapHalf + (r + 0.5) * kResolution);
          builder.add(p, intensity(p, rng));
        }
    const fs::path d = fs::temp_directory_path() / ("lidarloop_bench_wide_" + std::to_string(::getpid()));
    builder.save(d.string());
    return d.string();
  }();
  return dir;
}

// S of the road seen from the truth, placed at a prior (4 m, -3 m, 3 deg) off.
IntensityGrid road_grid() {
  const IntensityGridParams g;
  const Pose2d truth{2.0, 0.5, 1.0 * kDeg};
  const Pose2d prior = truth.compose(Pose2d{4.0, -3.0, 3.0 * kDeg}.inverse());
  std::mt19937 rng(2);
  std::vector<Eigen::Vector3d> points;
  std::vector<double> values;
  for (int r = 0; r < g.height_cells; ++r)
    for (int c = 0; c < g.width_cells; ++c)
      for (int k = 0; k < kSamplesPerCell; ++k) {
        const Eigen::Vector2d v((c + 0.5 - 0.5 * g.width_cells) * g.cell_m,
                                (r + 0.5 - 0.5 * g.height_cells) * g.cell_m);
        if (std::fabs(v.y()) > kRoadHalfWidth) continue;
        points.emplace_back(v.x(), v.y(), 0.0);
        values.push_back(intensity(truth.apply(v), rng));
      }
  return build_intensity_grid(points, values, prior, g);
}

// This thread's CPU time (ms): on a shared machine wall time counts other processes' turns too.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

void BM_WideApsStep(benchmark::State& state) {
  IntensityMap map(map_dir());
  const IntensityGrid S = road_grid();
  WideApsSearch search;
  int steps = 0, searches = 0;
  std::vector<double> step_ms;  // CPU time of each step of one search, summed over searches
  double slowest_ms = 0;
  for (auto _ : state) {
    const double start = thread_cpu_ms();
    search.step(S, map);
    const double ms = thread_cpu_ms() - start;
    slowest_ms = std::max(slowest_ms, ms);
    if (step_ms.size() <= size_t(steps)) step_ms.push_back(0);
    step_ms[size_t(steps)] += ms;
    ++steps;
    if (search.done()) {
      benchmark::DoNotOptimize(search.result().pose.x);
      ++searches;
      steps = 0;
      search.restart();
    }
  }
  state.counters["steps_per_search"] = double(step_ms.size());
  state.counters["slowest_step_cpu_ms"] = slowest_ms;
  for (size_t k = 0; k < step_ms.size() && searches > 0; ++k)
    state.counters["step" + std::to_string(k) + "_cpu_ms"] = step_ms[k] / searches;
}
BENCHMARK(BM_WideApsStep)->Unit(benchmark::kMillisecond);

void BM_WideApsOneShot(benchmark::State& state) {
  IntensityMap map(map_dir());
  const IntensityGrid S = road_grid();
  WideApsResult r;
  for (auto _ : state) benchmark::DoNotOptimize((r = wide_aps_search(S, map)).pose.x);
  state.counters["cells"] = r.cells_used;
  state.counters["offsets"] = double(r.offsets_evaluated);
  state.counters["terms"] = double(r.terms_evaluated);
}
BENCHMARK(BM_WideApsOneShot)->Unit(benchmark::kMillisecond);

// Streets every 40 m both ways, curbs 5 m either side of each centre line, points 0.1 m apart (as
// bench_curb_matching's city blocks); ~110 features (the campus drive's) seen from a pose 2.5 m off.
struct CityBlock {
  MapIndex index;
  Pose2d prior;
  std::vector<Eigen::Vector2d> features;
};

CityBlock city_block() {
  constexpr double kWindow = 32, kBlock = 40, kHalfWidth = 5, kSpacing = 0.1, kRange = 20;
  constexpr size_t kFeatures = 110;
  std::vector<Eigen::Vector2d> curbs;
  for (double centre = -kWindow; centre <= kWindow; centre += kBlock)
    for (double side : {-kHalfWidth, kHalfWidth})
      for (double t = -kWindow; t <= kWindow; t += kSpacing) {
        curbs.emplace_back(t, centre + side);
        curbs.emplace_back(centre + side, t);
      }
  const Pose2d truth{-12.0, 3.0, 0.0};
  const Pose2d prior = truth.compose(Pose2d{1.0, 2.5, 2.0 * kDeg}.inverse());
  std::vector<Eigen::Vector2d> near;
  for (const auto& c : curbs)
    if ((c - Eigen::Vector2d(truth.x, truth.y)).norm() < kRange) near.push_back(c);
  std::vector<Eigen::Vector2d> features;
  for (size_t k = 0; k < kFeatures; ++k)
    features.push_back(prior.apply(truth.inverse().apply(near[k * near.size() / kFeatures])));
  return {MapIndex(curbs), prior, features};
}

void BM_CurbHypothesesOneShot(benchmark::State& state) {
  const CityBlock c = city_block();
  CurbHypothesesResult r;
  for (auto _ : state) benchmark::DoNotOptimize((r = curb_hypotheses(c.features, c.index, c.prior)).best.pose.x);
  state.counters["icp_runs"] = r.icp_runs;
  state.counters["places"] = double(r.places.size());
}
BENCHMARK(BM_CurbHypothesesOneShot)->Unit(benchmark::kMillisecond);

// CurbHypothesisSearch run to the end, one step per iteration: the steps a search takes and the
// slowest step's CPU time (ms).
void BM_CurbHypothesesStep(benchmark::State& state) {
  const CityBlock c = city_block();
  CurbHypothesisSearch search;
  int steps = 0, searches = 0;
  double slowest_ms = 0;
  for (auto _ : state) {
    const double start = thread_cpu_ms();
    search.step(c.features, c.index, c.prior);
    slowest_ms = std::max(slowest_ms, thread_cpu_ms() - start);
    ++steps;
    if (search.done()) {
      benchmark::DoNotOptimize(search.result().best.pose.x);
      ++searches;
      search.restart();
    }
  }
  state.counters["steps_per_search"] = searches ? double(steps) / searches : 0.0;
  state.counters["slowest_step_cpu_ms"] = slowest_ms;
}
BENCHMARK(BM_CurbHypothesesStep)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop

BENCHMARK_MAIN();
