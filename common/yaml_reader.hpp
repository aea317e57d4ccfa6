#pragma once
// Strict reading of YAML files: every error names the file, line and column.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "common/input_error.hpp"

namespace lidarloop {

// "file:line:col" for a node (1-based), or just the file when the node has no position.
std::string yaml_location(const std::string& file, const YAML::Node& node);

class YamlReader {
 public:
  // Parses the file; a missing file or a syntax error is an InputError naming it.
  static YamlReader open(const std::string& path);
  // For YAML text that did not come from a file (tests, embedded defaults).
  static YamlReader from_string(const std::string& text, std::string name);

  const YAML::Node& root() const { return root_; }
  const std::string& file() const { return file_; }
  const std::string& text() const { return text_; }  // the YAML as read (for attachments in logs)

  [[noreturn]] void fail(const YAML::Node& at, const std::string& message) const;

  void expect_map(const YAML::Node& node, std::string_view what) const;
  void expect_sequence(const YAML::Node& node, std::string_view what) const;

  double number(const YAML::Node& node, std::string_view what) const;  // finite
  double number_in(const YAML::Node& node, std::string_view what, double lo, double hi) const;
  long integer_in(const YAML::Node& node, std::string_view what, long lo, long hi) const;
  bool boolean(const YAML::Node& node, std::string_view what) const;
  std::string string(const YAML::Node& node, std::string_view what) const;
  Eigen::Vector2d vec2(const YAML::Node& node, std::string_view what) const;
  Eigen::Vector3d vec3(const YAML::Node& node, std::string_view what) const;

 private:
  YamlReader(std::string file, std::string text, YAML::Node root)
      : file_(std::move(file)), text_(std::move(text)), root_(std::move(root)) {}
  std::string file_, text_;
  YAML::Node root_;
};

// One mapping of a YAML file, read key by key. Each read names a key the mapping may hold, so the
// list of allowed keys is the reads themselves; done() then reports any other key (a typo, a key of
// another section) at its own line and column. Optional reads overwrite a default only when the key
// is present, range-checked.
class YamlMap {
 public:
  // An absent `node` (a key not in the file) reads as an empty mapping: every value keeps its default.
  // Anything else must be a mapping.
  YamlMap(const YamlReader& reader, const YAML::Node& node, std::string_view what);

  const YamlReader& reader() const { return reader_; }
  const YAML::Node& node() const { return node_; }
  bool present() const { return node_.IsDefined(); }
  std::string where() const { return yaml_location(reader_.file(), node_); }

  // map[key], absent or not; either way `key` is one the mapping may hold.
  YAML::Node operator[](const char* key);
  // map[key], or an error at the mapping when it is absent.
  YAML::Node required(const char* key);

  YamlMap& number(const char* key, double& value, double lo, double hi);
  YamlMap& number(const char* key, std::optional<double>& value, double lo, double hi);
  // Written in degrees, kept in radians.
  YamlMap& degrees(const char* key, double& radians, double lo_deg, double hi_deg);
  YamlMap& integer(const char* key, int& value, int lo, int hi);
  YamlMap& integer(const char* key, int64_t& value, int64_t lo, int64_t hi);
  YamlMap& integer(const char* key, uint64_t& value, uint64_t lo, uint64_t hi);
  YamlMap& boolean(const char* key, bool& value);
  YamlMap& string(const char* key, std::string& value);
  YamlMap& vec2(const char* key, Eigen::Vector2d& value);
  YamlMap& vec3(const char* key, Eigen::Vector3d& value);

  // Call after the last read: a key no read named is unknown, a key given twice is ambiguous.
  void done() const;

 private:
  const YamlReader& reader_;
  YAML::Node node_;
  std::vector<std::string> keys_;
};

}  // namespace lidarloop
