#pragma once
// Command-line parsing for the `lidarloop` subcommands: declared options, `--name value` or
// `--name=value`, repeatable options, positional arguments; anything undeclared is a usage error.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/input_error.hpp"

namespace lidarloop {

struct OptionSpec {
  std::string name;        // without the leading dashes
  std::string value_name;  // empty for a flag that takes no value
  std::string help;
};

struct CommandSpec {
  std::string name, usage, summary;
  std::vector<OptionSpec> options;
  int min_positional = 0, max_positional = 0;
};

class Args {
 public:
  bool flag(const std::string& name) const { return values_.count(name) > 0; }
  std::optional<std::string> value(const std::string& name) const;
  std::vector<std::string> values(const std::string& name) const;
  std::string text(const std::string& name, const std::string& fallback) const;
  double number(const std::string& name, double fallback) const;
  long integer(const std::string& name, long fallback, long lo, long hi) const;
  // A comma-separated list of exactly `count` numbers, e.g. --pose X,Y,YAW.
  std::vector<double> numbers(const std::string& name, size_t count) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  friend Args parse_args(const CommandSpec&, const std::vector<std::string>&);
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
};

// Throws InputError for unknown options, missing values or a wrong number of positionals.
// `--help` is left in the result as a flag for the caller to print help().
Args parse_args(const CommandSpec& spec, const std::vector<std::string>& argv);
std::string help(const CommandSpec& spec);
std::vector<double> parse_number_list(const std::string& text, size_t count, const std::string& what);

}  // namespace lidarloop
