// Curb matching's inner question, "which map curb is nearest to this point, if any within the gate?",
// answered by the KD-tree (MapIndex::nearest) and by the buckets (MapIndex::nearest_within) at global
// and local ICP's gates, on a city-block curb map of the size the localizer matches against (a 64 m
// window, points 0.1 m apart), and the whole probabilistic ICP (Table I: n_t = 30, n_p = 15) on a
// scan's worth of curbs.
//   build/benchmarks/bench_curb_matching
// Read the ratio of the two nearest-neighbour benchmarks, not their absolute times.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "localizer/probabilistic_icp.hpp"

namespace lidarloop {
namespace {

constexpr double kSpacing = 0.1;     // m between map curb points (CurbLayer's default)
constexpr double kWindow = 32.0;     // m, half size of the localizer's map window
constexpr double kBlock = 40.0;      // m between street centre lines
constexpr double kRoadWidth = 10.0;  // m between the curbs of a street
constexpr double kGate = 1.0;        // m, the paper's d_g (global ICP's gate)
constexpr double kLocalGate = 2.0;   // m, local ICP's gate (IcpParams::max_correspondence)
constexpr double kCurbNoise = 0.3;   // m: detected curbs around the true ones, as after a pose error
constexpr double kOutliers = 0.2;    // fraction of detections that are not curbs at all
constexpr size_t kQueries = 4096;
constexpr size_t kScanCurbs = 110;  // curb features per scan on the campus drive

// Streets every kBlock metres both ways; each has a curb either side of its centre line.
std::vector<Eigen::Vector2d> city_blocks() {
  std::vector<Eigen::Vector2d> m;
  for (double centre = -kWindow; centre <= kWindow; centre += kBlock)
    for (double side : {-0.5 * kRoadWidth, 0.5 * kRoadWidth})
      for (double t = -kWindow; t <= kWindow; t += kSpacing) {
        m.emplace_back(t, centre + side);  // along x
        m.emplace_back(centre + side, t);  // along y
      }
  return m;
}

std::vector<Eigen::Vector2d> detections(const std::vector<Eigen::Vector2d>& map, size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, kCurbNoise);
  std::uniform_real_distribution<double> anywhere(-kWindow, kWindow), coin(0.0, 1.0);
  std::uniform_int_distribution<size_t> pick(0, map.size() - 1);
  std::vector<Eigen::Vector2d> q;
  for (size_t i = 0; i < n; ++i)
    q.push_back(coin(rng) < kOutliers ? Eigen::Vector2d(anywhere(rng), anywhere(rng))
                                      : Eigen::Vector2d(map[pick(rng)] + Eigen::Vector2d(noise(rng), noise(rng))));
  return q;
}

// The gate is the benchmark's argument, in decimetres.
void BM_NearestKdTree(benchmark::State& state) {
  const MapIndex index(city_blocks());
  const auto queries = detections(index.points(), kQueries, 1);
  const double gate = 0.1 * double(state.range(0));
  for (auto _ : state)
    for (const auto& q : queries) {
      const auto found = index.nearest(q);
      benchmark::DoNotOptimize(found.second <= gate ? found.first : SIZE_MAX);
    }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(queries.size()));
}
BENCHMARK(BM_NearestKdTree)->Arg(int(10 * kGate))->Arg(int(10 * kLocalGate));

void BM_NearestWithinBuckets(benchmark::State& state) {
  const MapIndex index(city_blocks());
  const auto queries = detections(index.points(), kQueries, 1);
  const double gate = 0.1 * double(state.range(0));
  for (auto _ : state)
    for (const auto& q : queries) benchmark::DoNotOptimize(index.nearest_within(q, gate).first);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(queries.size()));
}
BENCHMARK(BM_NearestWithinBuckets)->Arg(int(10 * kGate))->Arg(int(10 * kLocalGate));

void BM_BuildIndex(benchmark::State& state) {
  const auto map = city_blocks();
  for (auto _ : state) benchmark::DoNotOptimize(MapIndex(map).empty());
}
BENCHMARK(BM_BuildIndex);

void BM_ProbabilisticIcp(benchmark::State& state) {
  const MapIndex index(city_blocks());
  // A scan's curbs seen from a pose 0.5 m and 1 deg off.
  const Pose2d error{0.5, -0.3, 0.0175};
  std::vector<Eigen::Vector2d> curbs;
  for (const auto& q : detections(index.points(), kScanCurbs, 2)) curbs.push_back(error.inverse().apply(q));
  const ProbabilisticIcpParams params;
  std::mt19937_64 rng(3);
  for (auto _ : state) benchmark::DoNotOptimize(probabilistic_icp(index, curbs, {}, params, rng).t.x);
}
BENCHMARK(BM_ProbabilisticIcp)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarloop

BENCHMARK_MAIN();
