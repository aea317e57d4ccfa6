#pragma once
// Strict reading of YAML files: every error names the file, line and column.
#include <initializer_list>
#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "common/input_error.hpp"

namespace lidarloop {

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
  // Every key of `map` must be one of `allowed`; an unknown key is reported at its own position.
  void allow_keys(const YAML::Node& map, std::initializer_list<std::string_view> allowed) const;
  // map[key], or an error at the map's position when it is absent.
  YAML::Node required(const YAML::Node& map, const std::string& key) const;

  double number(const YAML::Node& node, std::string_view what) const;  // finite
  double number_in(const YAML::Node& node, std::string_view what, double lo, double hi) const;
  long integer_in(const YAML::Node& node, std::string_view what, long lo, long hi) const;
  // Overwrites `value` with map[key] when the key is present (range-checked); keeps it otherwise.
  void read_number(const YAML::Node& map, const char* key, double& value, double lo, double hi) const;
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

// "file:line:col" for a node (1-based), or just the file when the node has no position.
std::string yaml_location(const std::string& file, const YAML::Node& node);

}  // namespace lidarloop
