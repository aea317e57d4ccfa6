// lidarloop sweep: one scenario, a grid of variations, seeds and methods, run as a pool of processes
// (or as one shard of many on a cluster), and the report of error and failure rate against each
// varied parameter and against the curb actually hidden.
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <thread>

#include "common/input_error.hpp"
#include "loop/localizer_setup.hpp"
#include "mapping/map_cache.hpp"
#include "scoring/result_files.hpp"
#include "sim/world_assets.hpp"
#include "sweep/process_pool.hpp"
#include "sweep/sweep_plan.hpp"
#include "sweep/sweep_report.hpp"
#include "tools/cluster_render.hpp"
#include "tools/commands.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr int kSecondsPerMinute = 60;

std::string default_out(const std::string& sweep_file) { return "out/sweeps/" + fs::path(sweep_file).stem().string(); }

// Written whole or not at all: shards on a shared volume write the same files side by side.
void write_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  write_text_file(tmp, text);
  fs::rename(tmp, path);
}

long env_number(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return -1;
  char* end = nullptr;
  const long n = std::strtol(v, &end, 10);
  if (*end || n < 0) throw InputError(std::string("$") + name + " is not a number: '" + v + "'");
  return n;
}

// --shard I/N, else the index a cluster engine gives each task of an array.
Shard shard_of(const Args& args) {
  if (const auto s = args.value("shard")) return parse_shard(*s);
  const long shards = args.value("shards") ? args.integer("shards", 1, 1, 1L << 20) : -1;
  if (const long k8s = env_number("JOB_COMPLETION_INDEX"); k8s >= 0) {
    if (shards < 0)
      throw InputError(
          "$JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job): give --shards N, the Job's completions");
    return parse_shard(std::to_string(k8s) + "/" + std::to_string(shards));
  }
  if (const long task = env_number("SLURM_ARRAY_TASK_ID"); task >= 0) {
    const long first = std::max(0L, env_number("SLURM_ARRAY_TASK_MIN"));
    const long count = shards >= 0 ? shards : env_number("SLURM_ARRAY_TASK_COUNT");
    if (count <= 0) throw InputError("$SLURM_ARRAY_TASK_ID is set but not $SLURM_ARRAY_TASK_COUNT: give --shards N");
    return parse_shard(std::to_string(task - first) + "/" + std::to_string(count));
  }
  if (shards > 1) throw InputError("--shards needs $JOB_COMPLETION_INDEX or $SLURM_ARRAY_TASK_ID; or give --shard I/N");
  return {};
}

std::string duration_text(double s) {
  const long t = long(s + 0.5);
  char out[32];
  if (t >= kSecondsPerMinute)
    std::snprintf(out, sizeof out, "%ldm%02lds", t / kSecondsPerMinute, t % kSecondsPerMinute);
  else
    std::snprintf(out, sizeof out, "%lds", t);
  return out;
}

// Checks every run of the shard against its world (paths on the road network, localizer settings)
// and builds each map the runs need once, before any run starts: the runs then only read it.
void prepare(const SweepSpec& spec, const std::vector<const SweepRun*>& runs) {
  std::map<std::string, LoadedWorld> worlds;
  std::set<std::string> maps;
  const VehicleParams vehicle = load_vehicle_params(data_dir() + "/assets/vehicle.yaml");
  for (const SweepRun* r : runs) {
    try {
      const Scenario s = parse_scenario(r->scenario_text, spec.scenario_file, vehicle);
      auto it = worlds.find(s.world);
      if (it == worlds.end()) it = worlds.emplace(s.world, load_scenario_world(s)).first;
      resolve_scenario(s, it->second.description, it->second.world);
      localizer_params_for(s);
      const MappingOptions options = scenario_mapping_options(s);
      if (maps.insert(s.world + " " + options.describe()).second) {
        const MapLocation map = ensure_map(s.world, options, false);
        std::printf("map        %s (%s)\n", map.dir.c_str(),
                    map.built ? ("built in " + duration_text(map.build_s)).c_str() : "found in the cache");
      }
    } catch (const InputError& e) {
      throw InputError(spec.file + ": run " + r->id + ": " + e.what());
    }
  }
}

// `deadline_ms`: --deadline-ms as given to the sweep, for every run, or empty.
PoolTask task_for(const SweepSpec& spec, const SweepRun& run, const std::string& run_dir, int threads,
                  const std::optional<std::string>& deadline_ms) {
  PoolTask t;
  t.argv = {self_executable()};
  const std::string scenario = run_dir + "/scenario.yaml";
  if (run.methods.size() == 1) {
    t.argv.insert(t.argv.end(),
                  {"run", scenario, "--method", run.methods[0], "--out", run_dir + "/" + method_label(run.methods[0])});
  } else {
    t.argv.insert(t.argv.end(), {"compare", scenario, "--out", run_dir});
    for (const auto& m : run.methods) t.argv.insert(t.argv.end(), {"--method", m});  // exec: lines may hold commas
  }
  t.argv.insert(t.argv.end(), {"--threads", std::to_string(threads)});
  if (deadline_ms) t.argv.insert(t.argv.end(), {"--deadline-ms", *deadline_ms});
  t.log_path = run_dir + "/log.txt";
  t.timeout_s = spec.timeout_s;
  return t;
}

RunEnd run_end_of(const PoolTaskEnd& e, double timeout_s) {
  RunEnd end;
  end.wall_s = e.wall_s;
  switch (e.how) {
    case PoolTaskEnd::How::exited:
      end.exit_code = e.code;
      // 0 and 1 are a finished run (1: it missed a threshold); 2 is bad input; anything else a failure.
      end.status = e.code <= 1 ? RunStatus::done : e.code == 2 ? RunStatus::error : RunStatus::crashed;
      if (end.status != RunStatus::done) end.detail = "exit code " + std::to_string(e.code) + " (see log.txt)";
      break;
    case PoolTaskEnd::How::signalled:
      end.status = RunStatus::crashed, end.signal = e.code;
      end.detail = std::string("killed by signal ") + std::to_string(e.code) + " (" + strsignal(e.code) + ")";
      break;
    case PoolTaskEnd::How::timed_out:
      end.status = RunStatus::timeout;
      end.detail = "stopped after " + std::to_string(int(timeout_s)) + " s (the sweep's timeout_s)";
      break;
    case PoolTaskEnd::How::not_started:
      end.status = RunStatus::error, end.exit_code = e.code;
      end.detail = "could not start lidarloop";
      break;
  }
  return end;
}

// The report of the sweep whose outputs are in `dirs` (one folder, or shards' folders), into `out`.
// Returns the number of runs no folder has finished.
size_t report(const std::vector<std::string>& dirs, const std::string& out) {
  const SweepPlan plan = read_sweep_plan(dirs.front() + "/sweep.json");
  for (size_t k = 1; k < dirs.size(); ++k)
    if (read_sweep_plan(dirs[k] + "/sweep.json").digest != plan.digest)
      throw InputError(dirs[k] + ": the outputs of another sweep (or of another version of " + plan.sweep_file +
                       ") than " + dirs.front());
  std::vector<RunResult> results;
  size_t missing = 0;
  for (const SweepRun& run : plan.runs) {
    RunResult best;
    for (const auto& dir : dirs) {
      RunResult r = read_run_result(dir + "/runs/" + run.id, run, plan.metrics);
      if (r.end.status == RunStatus::done || best.end.status == RunStatus::missing) best = std::move(r);
      if (best.end.status == RunStatus::done) break;
    }
    missing += best.end.status == RunStatus::missing;
    results.push_back(std::move(best));
  }
  fs::create_directories(out);
  write_sweep_report(out, plan, results);
  std::map<std::string, size_t> counts;
  for (const auto& r : results) ++counts[run_status_name(r.end.status)];
  std::printf("report     %s/ (sweep.csv, sweep.md, plots/): %zu runs:", out.c_str(), results.size());
  for (const auto& [name, n] : counts) std::printf(" %zu %s", n, name.c_str());
  std::printf("\n");
  return missing;
}

int run_merge(const Args& args) {
  const std::vector<std::string> dirs(args.positional().begin() + 1, args.positional().end());
  if (dirs.empty()) throw InputError("sweep merge: give the output folders of the sweep's shards");
  const size_t missing = report(dirs, args.text("out", dirs.front()));
  if (missing) std::printf("missing    %zu runs no folder holds (a shard not run yet, or not given)\n", missing);
  return missing ? 1 : 0;
}

int run_render(const Args& args) {
  if (args.positional().size() != 2) throw InputError("sweep render: give one sweep file");
  const std::string file = args.positional()[1];
  const SweepSpec spec = load_sweep(file);
  ClusterJob job;
  job.engine = args.text("engine", "");
  job.sweep_file = file;
  job.name = fs::path(file).stem().string();
  job.shards = int(args.integer("shards", 4, 1, 100000));
  job.jobs_per_shard = int(args.integer("jobs", 2, 1, 1024));
  job.image = args.text("image", job.image);
  job.lidarloop = args.text("lidarloop", job.lidarloop);
  job.results = args.text("results", "/data/sweeps/" + job.name);
  const std::string out = args.text("out", "out/cluster/" + job.name);
  fs::create_directories(out);
  const size_t runs = expand_sweep(spec).size();
  for (const auto& [name, text] : render_cluster_job(job)) {
    write_text_file(out + "/" + name, text);
    std::printf("wrote      %s/%s\n", out.c_str(), name.c_str());
  }
  std::printf("sweep      %s: %zu runs in %d shards (%zu to %zu runs each), %d processes per shard\n", file.c_str(),
              runs, job.shards, runs / size_t(job.shards), (runs + size_t(job.shards) - 1) / size_t(job.shards),
              job.jobs_per_shard);
  return 0;
}

int run_sweep(const Args& args) {
  const std::string& first = args.positional().at(0);
  if (first == "merge") return run_merge(args);
  if (first == "render") return run_render(args);
  if (args.positional().size() != 1)
    throw InputError("sweep: give one sweep file (or: sweep merge DIR..., sweep render FILE)");

  const SweepSpec spec = load_sweep(first);
  const std::vector<SweepRun> runs = expand_sweep(spec);
  const Shard shard = shard_of(args);
  const std::string out = args.text("out", default_out(first));
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = int(args.integer("jobs", cores, 1, 1024));
  const int threads = std::max(1, cores / jobs);
  LocalizerParams checked;  // --deadline-ms is checked here, once, rather than failing every run
  apply_deadline_option(args, checked);

  fs::create_directories(out + "/runs");
  const SweepPlan plan = make_sweep_plan(spec, runs);
  const std::string plan_path = out + "/sweep.json";
  if (fs::exists(plan_path) && read_sweep_plan(plan_path).digest != plan.digest)
    throw InputError(out + ": holds the outputs of another sweep (or of an earlier version of " + first +
                     "); give another --out or remove it");
  write_atomically(plan_path, sweep_plan_json(plan));

  std::vector<const SweepRun*> mine, pending;
  for (const SweepRun& r : runs)
    if (shard.contains(r.index)) mine.push_back(&r);
  for (const SweepRun* r : mine)
    if (read_run_end(out + "/runs/" + r->id).status != RunStatus::done) pending.push_back(r);
  std::printf("sweep      %s: %zu runs", first.c_str(), runs.size());
  if (shard.count > 1) std::printf(", shard %zu/%zu has %zu", shard.index, shard.count, mine.size());
  std::printf("; %zu already complete, %zu to run with %d processes of %d thread(s)\n", mine.size() - pending.size(),
              pending.size(), jobs, threads);
  prepare(spec, pending);
  std::fflush(stdout);  // a pod's or a batch job's log shows what it is doing before the first run ends
  if (args.flag("dry-run")) {
    for (const SweepRun* r : pending) {
      std::printf("run %s   ", r->id.c_str());
      for (size_t a = 0; a < spec.axes.size(); ++a)
        std::printf(" %s=%s", spec.axes[a].name.c_str(), spec.axes[a].levels[r->level[a]].label.c_str());
      std::printf(" seed=%llu\n", (unsigned long long)r->seed);
    }
    return 0;
  }

  std::vector<PoolTask> tasks;
  for (const SweepRun* r : pending) {
    const std::string dir = out + "/runs/" + r->id;
    fs::remove_all(dir);  // whatever an unfinished attempt left
    fs::create_directories(dir);
    write_text_file(dir + "/scenario.yaml", r->scenario_text);
    tasks.push_back(task_for(spec, *r, dir, threads, args.value("deadline-ms")));
  }
  const bool terminal = isatty(STDOUT_FILENO) != 0;
  size_t unfinished = 0;
  const bool whole = run_process_pool(
      tasks, jobs,
      [&](size_t k, const PoolTaskEnd& e) {
        if (e.interrupted) return;  // not recorded: the next invocation runs it again
        const RunEnd end = run_end_of(e, spec.timeout_s);
        unfinished += end.status != RunStatus::done;
        write_atomically(out + "/runs/" + pending[k]->id + "/status.json", run_end_json(end));
        if (end.status != RunStatus::done) {
          if (terminal) std::printf("\r%80s\r", "");
          std::printf("run %s    %s: %s\n", pending[k]->id.c_str(), run_status_name(end.status), end.detail.c_str());
          std::fflush(stdout);
        }
      },
      [&](const PoolProgress& p) {
        if (!terminal) return;
        const double rate = p.finished ? p.elapsed_s / double(p.finished) : 0;
        // The pool's throughput so far, over what is left.
        const std::string eta = p.finished ? duration_text(rate * double(p.total - p.finished)) : "?";
        std::printf("\rsweep %zu/%zu runs (%d%%), %zu running, %zu not done, %s elapsed, eta %s   ", p.finished,
                    p.total, int(100 * p.finished / std::max<size_t>(1, p.total)), p.running, unfinished,
                    duration_text(p.elapsed_s).c_str(), eta.c_str());
        std::fflush(stdout);
      });
  if (terminal) std::printf("\r%100s\r", "");
  if (!whole) {
    std::printf("interrupted: the runs that finished are kept; the same command resumes the sweep\n");
    return 130;
  }
  if (shard.count > 1) {
    std::printf(
        "shard      %zu/%zu finished (%zu of its runs not done); join the shards' folders with:\n"
        "           lidarloop sweep merge %s [OTHER_SHARD_FOLDERS...]\n",
        shard.index, shard.count, unfinished, out.c_str());
    return unfinished ? 1 : 0;
  }
  const size_t missing = report({out}, out);
  return unfinished || missing ? 1 : 0;
}

}  // namespace

Command sweep_command() {
  return {
      {"sweep",
       "lidarloop sweep SWEEP.yaml [--jobs N] [--out DIR] [--shard I/N | --shards N] [--dry-run]\n"
       "       lidarloop sweep merge DIR... [--out DIR]\n"
       "       lidarloop sweep render SWEEP.yaml --engine kubernetes|slurm [--shards N] [--jobs N] [--image IMAGE]\n"
       "                              [--results DIR] [--lidarloop PATH] [--out DIR]",
       "Run a stress sweep: a base scenario over a grid of variations, seeds and methods, as a pool of\n"
       "processes, and report each metric and the failure rate against each varied parameter and\n"
       "against the fraction of the curb traffic hid (sweep.csv, sweep.md, plots/). Runs already\n"
       "complete in DIR are skipped (resume). With --shard I/N (or in a Kubernetes Indexed Job or a\n"
       "Slurm array) it runs only its share; `merge` joins the shards' folders into the report;\n"
       "`render` writes the Kubernetes Job or the Slurm script for a sweep. Exit 0 when every run\n"
       "finished (a run missing a threshold counts as finished: it is data), 1 when one crashed, timed\n"
       "out or is missing, 2 on bad input, 130 when interrupted.",
       {{"jobs", "N", "runs at once (default: the number of cores); each gets cores/N threads"},
        {"out", "DIR", "output folder (default out/sweeps/<sweep name>); merge and render: where the result goes"},
        {"shard", "I/N", "run only shard I of N (0 <= I < N): the runs whose index is I modulo N"},
        {"dry-run", "", "check every run's scenario and build the maps, list the runs, run none"},
        {"deadline-ms", "MS", "every run's exec: localizer's per-scan deadline (default: each scenario's, else 100)"},
        {"shards", "N", "the number of shards when the index comes from $JOB_COMPLETION_INDEX or $SLURM_ARRAY_TASK_ID"},
        {"engine", "NAME", "render: kubernetes or slurm"},
        {"image", "IMAGE", "render: the container image with lidarloop built (Kubernetes)"},
        {"results", "DIR", "render: the shared folder the shards write to (default /data/sweeps/<name>)"},
        {"lidarloop", "PATH", "render: the lidarloop executable on the cluster's nodes"}},
       1,
       1000},
      run_sweep};
}

}  // namespace lidarloop
