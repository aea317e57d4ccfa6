#include "sweep/sweep_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "common/crc32.hpp"
#include "common/localizer_method.hpp"
#include "common/yaml_path.hpp"
#include "common/yaml_reader.hpp"
#include "localizer/localizer_params.hpp"
#include "sim/scenario.hpp"
#include "sweep/sweep_expression.hpp"

namespace lidarloop {
namespace {

namespace fs = std::filesystem;

constexpr double kDefaultTimeout_s = 600;  // a 60 s scenario runs in well under a minute on one core
constexpr size_t kMaxRuns = 100000;        // a grid this large is a typo
constexpr size_t kMaxRangeLevels = 1000;
constexpr int kNumberDigits = 12;  // derived values written into scenarios

std::string format_number(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.*g", kNumberDigits, v);
  return s;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// A scalar's number, or NaN for a word.
double number_of(const YAML::Node& scalar) {
  double v = 0;
  if (YAML::convert<double>::decode(scalar, v) && std::isfinite(v)) return v;
  return std::numeric_limits<double>::quiet_NaN();
}

// Fails at `at` unless `path` can be set in the base scenario (a list index must exist there).
void check_path(const YamlReader& y, const YAML::Node& at, const std::string& path, const YAML::Node& scenario) {
  try {
    YAML::Node copy = YAML::Clone(scenario);
    yaml_node_at(copy, path);
  } catch (const InputError& e) {
    y.fail(at, e.what());
  }
}

SweepAxis read_axis(const YamlReader& y, const YAML::Node& n, const YAML::Node& scenario) {
  YamlMap m(y, n, "a grid axis");
  SweepAxis axis;
  axis.where = m.where();
  std::string path;
  m.string("name", axis.name).string("path", path);
  if (axis.name.empty()) axis.name = path;
  if (axis.name.empty()) y.fail(n, "a grid axis needs a name or a path");
  if (!path.empty()) check_path(y, m["path"], path, scenario);
  const YAML::Node values = m["values"], levels = m["levels"], range = m["range"], zip = m["zip"];
  if (int(bool(values)) + int(bool(levels)) + int(bool(range)) + int(bool(zip)) != 1)
    y.fail(n, "axis '" + axis.name + "': give exactly one of values, levels, range or zip");
  if (zip && !path.empty()) y.fail(m["path"], "axis '" + axis.name + "': a zip sets its own paths; drop `path`");
  auto add = [&](const std::string& label, double value, const YAML::Node& scalar) {
    SweepLevel level{label, value, {}};
    if (!path.empty()) level.sets.emplace_back(path, scalar);
    axis.levels.push_back(std::move(level));
  };
  if (values) {
    y.expect_sequence(values, "values");
    for (const auto& v : values) {
      if (!v.IsScalar()) y.fail(v, "axis '" + axis.name + "': a value must be a number or a word");
      add(v.Scalar(), number_of(v), v);
    }
  } else if (levels) {
    y.expect_map(levels, "levels");
    for (const auto& kv : levels) add(kv.first.Scalar(), y.number(kv.second, "a level's number"), kv.second);
  } else if (range) {
    double from = 0, to = 0, step = 0;
    YamlMap r(y, range, "range");
    r.number("from", from, -1e9, 1e9).number("to", to, -1e9, 1e9).number("step", step, 1e-9, 1e9);
    r.required("from"), r.required("to"), r.required("step");
    r.done();
    if (to < from) y.fail(range, "range: `to` is below `from`");
    const size_t count = size_t(std::floor((to - from) / step + 1e-9)) + 1;
    if (count > kMaxRangeLevels) y.fail(range, "range: more than " + std::to_string(kMaxRangeLevels) + " levels");
    for (size_t k = 0; k < count; ++k) {
      const double v = from + double(k) * step;
      add(format_number(v), v, YAML::Node(format_number(v)));
    }
  } else {
    y.expect_map(zip, "zip");
    size_t count = 0;
    bool first = true;
    for (const auto& kv : zip) {
      const std::string zpath = kv.first.Scalar();
      check_path(y, kv.first, zpath, scenario);
      y.expect_sequence(kv.second, "a zip's list");
      if (first) {
        count = kv.second.size();
        for (const auto& v : kv.second) {
          if (!v.IsScalar()) y.fail(v, "a zip's values must be numbers or words");
          axis.levels.push_back({v.Scalar(), number_of(v), {}});
        }
      } else if (kv.second.size() != count) {
        y.fail(kv.second, "zip '" + zpath + "' has " + std::to_string(kv.second.size()) + " values, the first list " +
                              std::to_string(count));
      }
      for (size_t k = 0; k < count; ++k) {
        if (!kv.second[k].IsScalar()) y.fail(kv.second[k], "a zip's values must be numbers or words");
        axis.levels[k].sets.emplace_back(zpath, kv.second[k]);
      }
      first = false;
    }
  }
  m.done();
  if (axis.levels.empty()) y.fail(n, "axis '" + axis.name + "' has no levels");
  std::set<std::string> labels;
  for (const auto& l : axis.levels)
    if (!labels.insert(l.label).second) y.fail(n, "axis '" + axis.name + "': level '" + l.label + "' appears twice");
  return axis;
}

std::vector<std::string> read_words(const YamlReader& y, const YAML::Node& n, const char* what) {
  std::vector<std::string> out;
  y.expect_sequence(n, what);
  for (const auto& v : n) out.push_back(y.string(v, what));
  if (out.empty()) y.fail(n, std::string(what) + " is empty");
  return out;
}

// Sets `path` in `doc` to a scalar; the path was checked against the base, but copies and earlier sets
// can change what is there, so errors still name the run.
void set_scalar(YAML::Node doc, const std::string& path, const YAML::Node& scalar) {
  YAML::Node at = yaml_node_at(doc, path);
  at = YAML::Clone(scalar);
}

}  // namespace

bool SweepAxis::numeric() const {
  return std::all_of(levels.begin(), levels.end(), [](const SweepLevel& l) { return std::isfinite(l.value); });
}

const std::vector<std::string>& sweep_metric_names() {
  static const std::vector<std::string> names = {"lateral_rmse_m",     "longitudinal_rmse_m",  "heading_rmse_deg",
                                                 "position_rmse_m",    "max_position_error_m", "max_lateral_m",
                                                 "max_longitudinal_m", "max_heading_deg",      "latency_p50_ms",
                                                 "latency_p99_ms",     "max_lane_offset_m"};
  return names;
}

std::vector<uint64_t> parse_seed_list(const std::string& text, const std::string& what) {
  std::vector<uint64_t> seeds;
  auto number = [&](const std::string& s) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) throw std::invalid_argument(s);
    return std::stoull(s);
  };
  try {
    const size_t dash = text.find('-');
    if (dash != std::string::npos) {
      const uint64_t first = number(text.substr(0, dash)), last = number(text.substr(dash + 1));
      if (last < first || last - first >= kMaxSeeds) throw std::invalid_argument("range");
      for (uint64_t k = first; k <= last; ++k) seeds.push_back(k);
    } else {
      std::stringstream ss(text);
      for (std::string item; std::getline(ss, item, ',');) seeds.push_back(number(item));
    }
  } catch (const std::exception&) {
    throw InputError(what + ": expected a list like 1,2,3 or a range like 1-5, got '" + text + "'");
  }
  if (seeds.empty() || seeds.size() > kMaxSeeds)
    throw InputError(what + ": give 1 to " + std::to_string(kMaxSeeds) + " seeds");
  return seeds;
}

SweepSpec load_sweep(const std::string& path) {
  const YamlReader y = YamlReader::open(path);
  SweepSpec spec;
  spec.file = path;
  spec.text = y.text();
  YamlMap top(y, y.root(), "the sweep");
  if (!y.root().IsMap()) y.fail(y.root(), "a sweep must be a mapping (scenario, seeds, grid, ...)");

  std::string base;
  top.string("scenario", base);
  top.required("scenario");
  spec.scenario_file = (fs::path(path).parent_path() / base).lexically_normal().string();
  const YamlReader scenario_yaml = YamlReader::open(spec.scenario_file);
  spec.scenario_text = scenario_yaml.text();
  const Scenario scenario = parse_scenario(spec.scenario_text, spec.scenario_file);
  spec.closed_loop = scenario.closed_loop;

  if (const YAML::Node seeds = top["seeds"]) {
    if (seeds.IsSequence()) {
      for (const auto& s : seeds) spec.seeds.push_back(uint64_t(y.integer_in(s, "a seed", 0, 1L << 62)));
      if (spec.seeds.empty()) y.fail(seeds, "seeds is empty");
    } else {
      try {
        spec.seeds = parse_seed_list(y.string(seeds, "seeds"), "seeds");
      } catch (const InputError& e) {
        y.fail(seeds, e.what());
      }
    }
  } else {
    spec.seeds = {scenario.seed};
  }
  spec.methods = top["methods"] ? read_words(y, top["methods"], "methods") : std::vector{scenario.localizer_method};
  for (size_t k = 0; k < spec.methods.size(); ++k) {
    try {
      LocalizerParams params;
      set_method(params, spec.methods[k]);
    } catch (const std::exception& e) {
      y.fail(top["methods"][k], e.what());
    }
  }
  spec.metrics = top["metrics"] ? read_words(y, top["metrics"], "metrics")
                                : std::vector<std::string>{"lateral_rmse_m", "longitudinal_rmse_m", "heading_rmse_deg",
                                                           "max_position_error_m"};
  const auto& known = sweep_metric_names();
  for (size_t k = 0; k < spec.metrics.size(); ++k)
    if (std::find(known.begin(), known.end(), spec.metrics[k]) == known.end()) {
      std::string list;
      for (const auto& n : known) list += (list.empty() ? "" : ", ") + n;
      y.fail(top["metrics"][k], "unknown metric '" + spec.metrics[k] + "' (one of " + list + ")");
    }
  spec.timeout_s = kDefaultTimeout_s;
  top.number("timeout_s", spec.timeout_s, 1e-3, 1e7);

  const YAML::Node base_doc = YAML::Load(spec.scenario_text);
  const YAML::Node grid = top["grid"];
  if (grid) {
    y.expect_sequence(grid, "grid");
    for (const auto& a : grid) spec.axes.push_back(read_axis(y, a, base_doc));
  }
  std::set<std::string> names;
  for (const auto& a : spec.axes)
    if (!names.insert(a.name).second) y.fail(grid, "two grid axes are named '" + a.name + "'");

  // Expressions may use the numeric axes; check each against the first level of every axis.
  std::map<std::string, double> sample;
  for (const auto& a : spec.axes)
    if (is_identifier(a.name) && a.numeric()) sample[a.name] = a.levels.front().value;
  if (const YAML::Node set = top["set"]) {
    y.expect_map(set, "set");
    for (const auto& kv : set) {
      SweepSet s{kv.first.Scalar(), y.string(kv.second, "a set expression"), yaml_location(path, kv.first)};
      check_path(y, kv.first, s.path, base_doc);
      try {
        evaluate_expression(s.expression, sample);
      } catch (const InputError& e) {
        y.fail(kv.second, e.what());
      }
      spec.sets.push_back(std::move(s));
    }
  }
  if (const YAML::Node copies = top["copies"]) {
    YamlMap c(y, copies, "copies");
    SweepCopies out;
    out.where = c.where();
    c.string("of", out.of).string("count", out.count);
    c.required("of"), c.required("count");
    check_path(y, c["of"], out.of, base_doc);
    const auto steps = parse_yaml_path(out.of);
    if (!std::holds_alternative<size_t>(steps.back()))
      y.fail(c["of"], "copies: `of` must name a list entry, like traffic[0]");
    try {
      evaluate_expression(out.count, sample);
    } catch (const InputError& e) {
      y.fail(c["count"], e.what());
    }
    if (const YAML::Node shift = c["shift"]) {
      y.expect_map(shift, "shift");
      for (const auto& kv : shift) {
        check_path(y, kv.first, out.of + "." + kv.first.Scalar(), base_doc);
        out.shift.emplace_back(kv.first.Scalar(), y.number(kv.second, "a shift"));
      }
    }
    c.done();
    spec.copies = std::move(out);
  }
  top.done();

  size_t runs = spec.seeds.size() * (spec.closed_loop ? spec.methods.size() : 1);
  for (const auto& a : spec.axes) runs *= a.levels.size();
  if (runs > kMaxRuns)
    y.fail(y.root(), "the sweep has " + std::to_string(runs) + " runs, more than " + std::to_string(kMaxRuns));
  return spec;
}

std::vector<SweepRun> expand_sweep(const SweepSpec& spec) {
  size_t points = 1;
  for (const auto& a : spec.axes) points *= a.levels.size();
  const std::vector<std::vector<std::string>> method_groups =
      spec.closed_loop ? [&] {
        std::vector<std::vector<std::string>> g;
        for (const auto& m : spec.methods) g.push_back({m});
        return g;
      }()
                       : std::vector<std::vector<std::string>>{spec.methods};
  const size_t total = points * spec.seeds.size() * method_groups.size();
  const int width = std::max<int>(4, int(std::to_string(total - 1).size()));
  const YAML::Node base = YAML::Load(spec.scenario_text);

  std::vector<SweepRun> runs;
  runs.reserve(total);
  for (size_t p = 0; p < points; ++p) {
    std::vector<size_t> level(spec.axes.size());
    for (size_t a = spec.axes.size(), rest = p; a-- > 0;) {
      level[a] = rest % spec.axes[a].levels.size();
      rest /= spec.axes[a].levels.size();
    }
    YAML::Node doc = YAML::Clone(base);
    std::map<std::string, double> names;
    for (size_t a = 0; a < spec.axes.size(); ++a) {
      const SweepLevel& l = spec.axes[a].levels[level[a]];
      for (const auto& [path, scalar] : l.sets) set_scalar(doc, path, scalar);
      if (is_identifier(spec.axes[a].name) && std::isfinite(l.value)) names[spec.axes[a].name] = l.value;
    }
    for (const auto& s : spec.sets)
      set_scalar(doc, s.path, YAML::Node(format_number(evaluate_expression(s.expression, names))));
    if (spec.copies) {
      const SweepCopies& c = *spec.copies;
      const double count = evaluate_expression(c.count, names);
      if (count < 0 || count != std::floor(count))
        throw InputError(c.where + ": copies: count must be a whole number, at least 0, got " + format_number(count));
      const auto steps = parse_yaml_path(c.of);
      const size_t index = std::get<size_t>(steps.back());
      const std::string list_path = c.of.substr(0, c.of.rfind('['));
      YAML::Node list = yaml_node_at(doc, list_path);
      const YAML::Node original = YAML::Clone(list[index]);
      // The copies go after the original, keeping the index of every entry before it; count 0 removes it.
      YAML::Node rebuilt(YAML::NodeType::Sequence);
      for (size_t i = 0; i < list.size(); ++i) {
        if (i != index) {
          rebuilt.push_back(YAML::Clone(list[i]));
          continue;
        }
        if (count >= 1) rebuilt.push_back(YAML::Clone(original));
        for (int k = 1; k < int(count); ++k) {
          YAML::Node copy = YAML::Clone(original);
          for (const auto& [field, step] : c.shift) {
            YAML::Node at = yaml_node_at(copy, field);
            at = format_number(number_of(at) + step * k);
          }
          rebuilt.push_back(copy);
        }
      }
      YAML::Node at = yaml_node_at(doc, list_path);
      at = rebuilt;
    }
    for (const uint64_t seed : spec.seeds) {
      doc["seed"] = seed;
      YAML::Emitter out;
      out << doc;
      const std::string text = std::string(out.c_str()) + "\n";
      // The run's scenario must load: a level that breaks it fails here, not hours into the sweep.
      try {
        parse_scenario(text, spec.scenario_file);
      } catch (const InputError& e) {
        std::string levels;
        for (size_t a = 0; a < spec.axes.size(); ++a)
          levels += (a ? ", " : "") + spec.axes[a].name + " = " + spec.axes[a].levels[level[a]].label;
        char id[32];
        std::snprintf(id, sizeof id, "%0*zu", width, runs.size());
        throw InputError(spec.file + ": run " + id + " (" + levels + ", seed " + std::to_string(seed) +
                         ") makes a scenario that does not load: " + e.what());
      }
      for (const auto& methods : method_groups) {
        SweepRun r;
        r.index = runs.size();
        char id[32];
        std::snprintf(id, sizeof id, "%0*zu", width, r.index);
        r.id = id;
        r.level = level;
        r.seed = seed;
        r.methods = methods;
        r.scenario_text = text;
        runs.push_back(std::move(r));
      }
    }
  }
  return runs;
}

std::string sweep_digest(const SweepSpec& spec) {
  Crc32 crc;
  for (const std::string* s : {&spec.text, &spec.scenario_text}) {
    const uint64_t size = s->size();
    crc.update(&size, sizeof size);
    crc.update(s->data(), s->size());
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08x", crc.value());
  return hex;
}

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  try {
    const std::string index = text.substr(0, slash == std::string::npos ? 0 : slash);
    const std::string count = slash == std::string::npos ? "" : text.substr(slash + 1);
    for (const std::string* part : {&index, &count})
      if (part->empty() || part->find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument(text);
    const Shard s{std::stoul(text.substr(0, slash)), std::stoul(text.substr(slash + 1))};
    if (s.count == 0 || s.index >= s.count) throw std::invalid_argument(text);
    return s;
  } catch (const std::exception&) {
    throw InputError("--shard: expected I/N with 0 <= I < N (shard I of N), got '" + text + "'");
  }
}

}  // namespace lidarloop
