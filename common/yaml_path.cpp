#include "common/yaml_path.hpp"

#include <cctype>

#include "common/input_error.hpp"

namespace lidarloop {

std::vector<YamlPathStep> parse_yaml_path(const std::string& path) {
  auto bad = [&](const std::string& why) -> InputError {
    return InputError("'" + path + "' is not a path into the scenario (" + why + ")");
  };
  std::vector<YamlPathStep> steps;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '[') {
      const size_t close = path.find(']', i);
      if (close == std::string::npos || close == i + 1) throw bad("an index is written [N]");
      const std::string digits = path.substr(i + 1, close - i - 1);
      for (char c : digits)
        if (!std::isdigit(static_cast<unsigned char>(c))) throw bad("an index is written [N]");
      steps.emplace_back(size_t(std::stoul(digits)));
      i = close + 1;
    } else {
      if (path[i] == '.') {
        if (steps.empty()) throw bad("it starts with a dot");
        ++i;
      } else if (!steps.empty()) {
        throw bad("expected '.' or '[' after a step");
      }
      size_t end = i;
      while (end < path.size() && path[end] != '.' && path[end] != '[') ++end;
      if (end == i) throw bad("an empty key");
      if (path.substr(i, end - i).find(']') != std::string::npos) throw bad("a stray ']'");
      steps.emplace_back(path.substr(i, end - i));
      i = end;
    }
  }
  if (steps.empty()) throw bad("it is empty");
  return steps;
}

YAML::Node yaml_node_at(YAML::Node root, const std::string& path) {
  YAML::Node node = root;
  std::string walked;
  for (const YamlPathStep& step : parse_yaml_path(path)) {
    if (const auto* key = std::get_if<std::string>(&step)) {
      if (node.IsDefined() && !node.IsMap() && !node.IsNull())
        throw InputError(path + ": '" + (walked.empty() ? "the scenario" : walked) + "' is not a mapping");
      node.reset(node[*key]);
      if (!walked.empty()) walked += '.';
      walked += *key;
    } else {
      const size_t index = std::get<size_t>(step);
      if (!node.IsSequence()) throw InputError(path + ": '" + walked + "' is not a list");
      if (index >= node.size())
        throw InputError(path + ": '" + walked + "' has " + std::to_string(node.size()) + " entries, no [" +
                         std::to_string(index) + "]");
      node.reset(node[index]);
      walked += '[';
      walked += std::to_string(index);
      walked += ']';
    }
  }
  return node;
}

}  // namespace lidarloop
