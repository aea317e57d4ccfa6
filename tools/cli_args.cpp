#include "tools/cli_args.hpp"

#include <cmath>
#include <sstream>

namespace lidarloop {

static double parse_number(const std::string& text, const std::string& what) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(v))
    throw InputError(what + ": '" + text + "' is not a finite number");
  return v;
}

std::vector<double> parse_number_list(const std::string& text, size_t count, const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(parse_number(item, what));
  if (out.size() != count)
    throw InputError(what + ": expected " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  return out;
}

std::optional<std::string> Args::value(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::vector<std::string> Args::values(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

std::string Args::text(const std::string& name, const std::string& fallback) const {
  return value(name).value_or(fallback);
}

double Args::number(const std::string& name, double fallback) const {
  const auto v = value(name);
  return v ? parse_number(*v, "--" + name) : fallback;
}

long Args::integer(const std::string& name, long fallback, long lo, long hi) const {
  const auto v = value(name);
  if (!v) return fallback;
  const double d = parse_number(*v, "--" + name);
  if (d != std::floor(d) || d < double(lo) || d > double(hi))
    throw InputError("--" + name + ": expected a whole number from " + std::to_string(lo) + " to " +
                     std::to_string(hi) + ", got '" + *v + "'");
  return long(d);
}

std::vector<double> Args::numbers(const std::string& name, size_t count) const {
  const auto v = value(name);
  if (!v) throw InputError("--" + name + " is required");
  return parse_number_list(*v, count, "--" + name);
}

Args parse_args(const CommandSpec& spec, const std::vector<std::string>& argv) {
  Args args;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a == "--help" || a == "-h") {
      args.values_["help"];
      continue;
    }
    if (a.rfind("--", 0) != 0 || a == "--") {
      args.positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2), value;
    const size_t eq = name.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) value = name.substr(eq + 1), name = name.substr(0, eq);
    const OptionSpec* opt = nullptr;
    for (const auto& o : spec.options)
      if (o.name == name) opt = &o;
    if (!opt) throw InputError("lidarloop " + spec.name + ": unknown option '--" + name + "' (see --help)");
    if (opt->value_name.empty()) {
      if (inline_value) throw InputError("lidarloop " + spec.name + ": --" + name + " takes no value");
      args.values_[name];
      continue;
    }
    if (!inline_value) {
      if (i + 1 >= argv.size()) throw InputError("lidarloop " + spec.name + ": --" + name + " needs a value");
      value = argv[++i];
    }
    args.values_[name].push_back(value);
  }
  if (args.flag("help")) return args;
  const int n = int(args.positional_.size());
  if (n < spec.min_positional || n > spec.max_positional)
    throw InputError("lidarloop " + spec.name + ": expected " +
                     (spec.min_positional == spec.max_positional
                          ? std::to_string(spec.min_positional)
                          : std::to_string(spec.min_positional) + " to " + std::to_string(spec.max_positional)) +
                     " positional argument(s), got " + std::to_string(n) + " (usage: " + spec.usage + ")");
  return args;
}

std::string help(const CommandSpec& spec) {
  std::ostringstream out;
  out << "usage: " << spec.usage << "\n\n" << spec.summary << "\n";
  if (!spec.options.empty()) out << "\noptions:\n";
  for (const auto& o : spec.options) {
    std::string left = "  --" + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
    if (left.size() < 30)
      left.resize(30, ' ');
    else
      left += "  ";
    out << left << o.help << "\n";
  }
  out << "  --help                      show this help\n";
  return out.str();
}

}  // namespace lidarloop
