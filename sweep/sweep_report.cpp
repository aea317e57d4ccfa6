#include "sweep/sweep_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/input_error.hpp"
#include "localizer/localizer_params.hpp"
#include "scoring/result_files.hpp"
#include "sweep/sweep_plots.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kJsonIndent = 2;
constexpr int kCsvDigits = 6;
constexpr int kHiddenBins = 10;  // the curb hidden, in tenths
const char* const kHidden = "curb_hidden_fraction";

// The file's text, or "" when there is none: a run not made yet.
std::string read_text(const std::string& path) { return read_text_file(path).value_or(""); }

std::string number(double v, int digits = kCsvDigits) {
  if (!std::isfinite(v)) return "";
  char s[40];
  std::snprintf(s, sizeof s, "%.*g", digits, v);
  return s;
}

// A file-name-safe version of an axis or metric name.
std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

// One method's outcome in one run, flattened for aggregation.
struct Row {
  const SweepRun* run;
  std::string method;
  RunStatus status;
  const MethodOutcome* outcome;  // null unless done
  bool failed() const { return !outcome || !outcome->pass; }
  double metric(const std::string& name) const {
    if (!outcome) return kNaN;
    const auto it = outcome->metrics.find(name);
    return it == outcome->metrics.end() ? kNaN : it->second;
  }
};

std::vector<Row> rows_of(const SweepPlan& plan, const std::vector<RunResult>& results) {
  std::vector<Row> rows;
  for (size_t i = 0; i < plan.runs.size(); ++i)
    for (const auto& m : plan.runs[i].methods) {
      const auto it = results[i].methods.find(m);
      rows.push_back({&plan.runs[i], m, results[i].end.status, it == results[i].methods.end() ? nullptr : &it->second});
    }
  return rows;
}

struct Summary {
  size_t runs = 0, completed = 0, failed = 0;
  double mean = kNaN, sd = kNaN, lo = kNaN, hi = kNaN;
};

Summary summarise(const std::vector<const Row*>& rows, const std::string& metric) {
  Summary s;
  std::vector<double> v;
  for (const Row* r : rows) {
    if (r->status == RunStatus::missing) continue;  // not run yet: neither a run nor a failure
    ++s.runs;
    s.completed += r->outcome != nullptr;
    s.failed += r->failed();
    if (const double x = r->metric(metric); std::isfinite(x)) v.push_back(x);
  }
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / double(v.size());
  double sq = 0;
  for (double x : v) sq += (x - s.mean) * (x - s.mean);
  s.sd = v.size() > 1 ? std::sqrt(sq / double(v.size() - 1)) : 0.0;
  s.lo = *std::min_element(v.begin(), v.end());
  s.hi = *std::max_element(v.begin(), v.end());
  return s;
}

std::string mean_sd(const Summary& s) {
  return std::isfinite(s.mean) ? number(s.mean, 3) + " ± " + number(s.sd, 2) : "–";
}

std::string percent(size_t part, size_t whole) {
  return whole ? number(100.0 * double(part) / double(whole), 3) + " %" : "–";
}

std::string status_counts(const std::vector<RunResult>& results) {
  std::map<std::string, size_t> counts;
  for (const auto& r : results) ++counts[run_status_name(r.end.status)];
  std::string out;
  for (const auto& [name, n] : counts) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + name;
  return out;
}

std::string markdown(const SweepPlan& plan, const std::vector<RunResult>& results, const std::vector<Row>& rows) {
  std::ostringstream md;
  md << "# Sweep " << plan.sweep_file << "\n\n";
  size_t seeds = 0;
  {
    std::set<uint64_t> s;
    for (const auto& r : plan.runs) s.insert(r.seed);
    seeds = s.size();
  }
  md << plan.runs.size() << " runs (" << seeds << " seeds; methods ";
  for (size_t k = 0; k < plan.methods.size(); ++k) md << (k ? ", " : "") << plan.methods[k];
  md << "): " << status_counts(results) << ". A run fails when it misses a threshold of the base scenario's "
     << "`pass`, or does not finish (error, crash, timeout); runs not made yet (missing) are left out. Each "
     << "cell: mean ± standard deviation over the completed runs at that level (all seeds and every level of "
     << "the other axes).\n";
  for (size_t a = 0; a < plan.axes.size(); ++a)
    for (const auto& method : plan.methods) {
      const SweepAxis& axis = plan.axes[a];
      md << "\n## " << method << " against " << axis.name << "\n\n| " << axis.name << " | runs | failed |";
      for (const auto& m : plan.metrics) md << " " << m << " |";
      md << " curb hidden |\n|---|---|---|";
      for (size_t k = 0; k <= plan.metrics.size(); ++k) md << "---|";
      md << "\n";
      for (size_t l = 0; l < axis.levels.size(); ++l) {
        std::vector<const Row*> at;
        for (const auto& r : rows)
          if (r.method == method && r.run->level[a] == l) at.push_back(&r);
        const Summary first = summarise(at, plan.metrics.front());
        md << "| " << axis.levels[l].label << " | " << first.runs << " | " << percent(first.failed, first.runs) << " |";
        for (const auto& m : plan.metrics) md << " " << mean_sd(summarise(at, m)) << " |";
        md << " " << mean_sd(summarise(at, kHidden)) << " |\n";
      }
    }
  md << "\n## Against the curb hidden (measured in each run)\n\n"
     << "The fraction of the curb within the sensor's reach that traffic hid, over the whole run, in bins of "
     << number(1.0 / kHiddenBins) << ".\n\n| curb hidden | method | runs | failed |";
  for (const auto& m : plan.metrics) md << " " << m << " |";
  md << "\n|---|---|---|---|";
  for (size_t k = 0; k < plan.metrics.size(); ++k) md << "---|";
  md << "\n";
  for (int b = 0; b < kHiddenBins; ++b)
    for (const auto& method : plan.methods) {
      std::vector<const Row*> at;
      for (const auto& r : rows) {
        const double h = r.metric(kHidden);
        if (r.method == method && std::isfinite(h) && std::min(int(h * kHiddenBins), kHiddenBins - 1) == b)
          at.push_back(&r);
      }
      if (at.empty()) continue;
      const Summary first = summarise(at, plan.metrics.front());
      md << "| " << number(double(b) / kHiddenBins) << "–" << number(double(b + 1) / kHiddenBins) << " | " << method
         << " | " << first.runs << " | " << percent(first.failed, first.runs) << " |";
      for (const auto& m : plan.metrics) md << " " << mean_sd(summarise(at, m)) << " |";
      md << "\n";
    }
  return md.str();
}

void plots(const std::string& dir, const SweepPlan& plan, const std::vector<Row>& rows) {
  fs::create_directories(dir);
  for (size_t a = 0; a < plan.axes.size(); ++a) {
    const SweepAxis& axis = plan.axes[a];
    std::vector<std::string> categories;
    if (!axis.numeric())
      for (const auto& l : axis.levels) categories.push_back(l.label);
    auto x_of = [&](size_t l) { return axis.numeric() ? axis.levels[l].value : double(l); };
    auto by_level = [&](const std::string& method, size_t l) {
      std::vector<const Row*> at;
      for (const auto& r : rows)
        if (r.method == method && r.run->level[a] == l) at.push_back(&r);
      return at;
    };
    for (const auto& metric : plan.metrics) {
      std::vector<Series> series;
      for (const auto& method : plan.methods) {
        Series s{method, {}};
        for (size_t l = 0; l < axis.levels.size(); ++l) {
          const Summary m = summarise(by_level(method, l), metric);
          s.points.push_back({x_of(l), m.mean, m.mean - m.sd, m.mean + m.sd});
        }
        series.push_back(std::move(s));
      }
      write_series_plot(dir + "/" + slug(metric) + "_vs_" + slug(axis.name) + ".png",
                        metric + " against " + axis.name + " (mean, bars: +-1 standard deviation)", axis.name,
                        categories, series);
    }
    std::vector<Series> failures;
    for (const auto& method : plan.methods) {
      Series s{method, {}};
      for (size_t l = 0; l < axis.levels.size(); ++l) {
        const Summary m = summarise(by_level(method, l), plan.metrics.front());
        const double rate = m.runs ? double(m.failed) / double(m.runs) : kNaN;
        s.points.push_back({x_of(l), rate, rate, rate});
      }
      failures.push_back(std::move(s));
    }
    write_series_plot(dir + "/failure_rate_vs_" + slug(axis.name) + ".png",
                      "failure rate against " + axis.name + " (thresholds of the base scenario)", axis.name, categories,
                      failures);
  }
  for (const auto& metric : plan.metrics) {
    std::vector<ScatterSeries> series;
    for (const auto& method : plan.methods) {
      ScatterSeries s{method, {}, {}};
      for (const auto& r : rows)
        if (r.method == method) s.x.push_back(r.metric(kHidden)), s.y.push_back(r.metric(metric));
      series.push_back(std::move(s));
    }
    write_scatter_plot(dir + "/" + slug(metric) + "_vs_curb_hidden.png",
                       metric + " against the fraction of the curb hidden (one circle per run)",
                       "fraction of the curb within reach hidden by traffic", series);
  }
}

}  // namespace

const char* run_status_name(RunStatus s) {
  switch (s) {
    case RunStatus::missing:
      return "missing";
    case RunStatus::done:
      return "done";
    case RunStatus::error:
      return "error";
    case RunStatus::crashed:
      return "crashed";
    case RunStatus::timeout:
      return "timeout";
  }
  return "missing";
}

SweepPlan make_sweep_plan(const SweepSpec& spec, const std::vector<SweepRun>& runs) {
  SweepPlan plan{spec.file, sweep_digest(spec), spec.axes, spec.methods, spec.metrics, runs};
  for (auto& a : plan.axes)
    for (auto& l : a.levels) l.sets.clear();
  for (auto& r : plan.runs) r.scenario_text.clear();
  return plan;
}

std::string sweep_plan_json(const SweepPlan& plan) {
  json axes = json::array(), runs = json::array();
  for (const auto& a : plan.axes) {
    json levels = json::array();
    for (const auto& l : a.levels)
      levels.push_back({{"label", l.label}, {"value", std::isfinite(l.value) ? json(l.value) : json(nullptr)}});
    axes.push_back({{"name", a.name}, {"levels", levels}});
  }
  for (const auto& r : plan.runs)
    runs.push_back({{"id", r.id}, {"level", r.level}, {"seed", r.seed}, {"methods", r.methods}});
  const json doc = {{"sweep", plan.sweep_file}, {"digest", plan.digest},   {"axes", axes},
                    {"methods", plan.methods},  {"metrics", plan.metrics}, {"runs", runs}};
  return doc.dump(kJsonIndent) + "\n";
}

SweepPlan read_sweep_plan(const std::string& path) {
  const std::string text = read_text(path);
  if (text.empty()) throw InputError(path + ": no sweep plan here (is this a sweep's output folder?)");
  try {
    const json doc = json::parse(text);
    SweepPlan plan;
    plan.sweep_file = doc.at("sweep").get<std::string>();
    plan.digest = doc.at("digest").get<std::string>();
    plan.methods = doc.at("methods").get<std::vector<std::string>>();
    plan.metrics = doc.at("metrics").get<std::vector<std::string>>();
    for (const auto& a : doc.at("axes")) {
      SweepAxis axis;
      axis.name = a.at("name").get<std::string>();
      for (const auto& l : a.at("levels"))
        axis.levels.push_back(
            {l.at("label").get<std::string>(), l.at("value").is_null() ? kNaN : l.at("value").get<double>(), {}});
      plan.axes.push_back(std::move(axis));
    }
    for (const auto& r : doc.at("runs")) {
      SweepRun run;
      run.index = plan.runs.size();
      run.id = r.at("id").get<std::string>();
      run.level = r.at("level").get<std::vector<size_t>>();
      run.seed = r.at("seed").get<uint64_t>();
      run.methods = r.at("methods").get<std::vector<std::string>>();
      if (run.level.size() != plan.axes.size()) throw InputError("a run's levels do not match the axes");
      for (size_t a = 0; a < run.level.size(); ++a)
        if (run.level[a] >= plan.axes[a].levels.size()) throw InputError("a run's level is out of range");
      plan.runs.push_back(std::move(run));
    }
    if (plan.metrics.empty() || plan.methods.empty()) throw InputError("no metrics or no methods");
    return plan;
  } catch (const json::exception& e) {
    throw InputError(path + ": not a sweep plan: " + e.what());
  } catch (const InputError& e) {
    throw InputError(path + ": not a sweep plan: " + e.what());
  }
}

std::string run_end_json(const RunEnd& end) {
  const json doc = {{"status", run_status_name(end.status)},
                    {"exit_code", end.exit_code},
                    {"signal", end.signal},
                    {"wall_s", end.wall_s},
                    {"detail", end.detail}};
  return doc.dump(kJsonIndent) + "\n";
}

RunEnd read_run_end(const std::string& run_dir) {
  RunEnd end;
  const std::string text = read_text(run_dir + "/status.json");
  if (text.empty()) return end;
  try {
    const json doc = json::parse(text);
    const std::string status = doc.at("status").get<std::string>();
    for (RunStatus s : {RunStatus::done, RunStatus::error, RunStatus::crashed, RunStatus::timeout})
      if (status == run_status_name(s)) end.status = s;
    end.exit_code = doc.at("exit_code").get<int>();
    end.signal = doc.at("signal").get<int>();
    end.wall_s = doc.at("wall_s").get<double>();
    end.detail = doc.at("detail").get<std::string>();
  } catch (const json::exception&) {
    return {};  // a status cut short by a killed machine: the run is redone
  }
  return end;
}

RunResult read_run_result(const std::string& run_dir, const SweepRun& run, const std::vector<std::string>& metrics) {
  RunResult result;
  result.end = read_run_end(run_dir);
  if (result.end.status != RunStatus::done) return result;
  for (const auto& method : run.methods) {
    const std::string path = run_dir + "/" + method_label(method) + "/metrics.json";
    MethodOutcome o;
    try {
      const json doc = json::parse(read_text(path));
      o.pass = doc.at("pass").get<bool>();
      for (const auto& m : metrics) {
        const json& v = doc.contains(m) ? doc.at(m) : json(nullptr);
        o.metrics[m] = v.is_number() ? v.get<double>() : kNaN;
      }
      const json& h = doc.contains(kHidden) ? doc.at(kHidden) : json(nullptr);
      o.metrics[kHidden] = h.is_number() ? h.get<double>() : kNaN;
    } catch (const json::exception& e) {
      result.end.status = RunStatus::crashed;
      result.end.detail = path + ": missing or unreadable";
      result.methods.clear();
      return result;
    }
    result.methods[method] = std::move(o);
  }
  return result;
}

std::string sweep_csv(const SweepPlan& plan, const std::vector<RunResult>& results) {
  std::ostringstream csv;
  csv << "run";
  for (const auto& a : plan.axes) csv << ',' << csv_field(a.name);
  csv << ",seed,method,status,pass";
  for (const auto& m : plan.metrics) csv << ',' << m;
  csv << ',' << kHidden << '\n';
  for (const Row& r : rows_of(plan, results)) {
    csv << r.run->id;
    for (size_t a = 0; a < plan.axes.size(); ++a) csv << ',' << csv_field(plan.axes[a].levels[r.run->level[a]].label);
    csv << ',' << r.run->seed << ',' << r.method << ',' << run_status_name(r.status) << ','
        << (r.outcome ? (r.outcome->pass ? "true" : "false") : "");
    for (const auto& m : plan.metrics) csv << ',' << number(r.metric(m));
    csv << ',' << number(r.metric(kHidden)) << '\n';
  }
  return csv.str();
}

void write_sweep_report(const std::string& dir, const SweepPlan& plan, const std::vector<RunResult>& results) {
  if (results.size() != plan.runs.size()) throw std::invalid_argument("write_sweep_report: one result per run");
  const std::vector<Row> rows = rows_of(plan, results);
  write_text_file(dir + "/sweep.csv", sweep_csv(plan, results));
  write_text_file(dir + "/sweep.md", markdown(plan, results, rows));
  plots(dir + "/plots", plan, rows);
}

}  // namespace lidarloop
