#pragma once
// Addressing a value inside a YAML document by a path such as `traffic[0].path.offset`: keys joined by
// dots, list elements by [index]. A sweep sets scenario values this way.
#include <string>
#include <variant>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace lidarloop {

// One step of a path: a mapping key or a list index.
using YamlPathStep = std::variant<std::string, size_t>;

// Splits a path into its steps; InputError (naming `path`) for an empty key, a bad index or a stray
// character.
std::vector<YamlPathStep> parse_yaml_path(const std::string& path);

// The node at `path` in `root`, creating mappings for missing keys on the way (a list index must
// exist). InputError naming the path when a step does not fit what is there (a key into a list, an
// index past the end).
YAML::Node yaml_node_at(YAML::Node root, const std::string& path);

}  // namespace lidarloop
