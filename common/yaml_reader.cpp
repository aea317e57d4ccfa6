#include "common/yaml_reader.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace lidarloop {

std::string yaml_location(const std::string& file, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null()) return file;
  return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

YamlReader YamlReader::open(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open file");
  std::stringstream text;
  text << in.rdbuf();
  return from_string(text.str(), path);
}

YamlReader YamlReader::from_string(const std::string& text, std::string name) {
  try {
    return YamlReader(name, text, YAML::Load(text));
  } catch (const YAML::Exception& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": YAML syntax error: " + e.msg);
  }
}

void YamlReader::fail(const YAML::Node& at, const std::string& message) const {
  throw InputError(yaml_location(file_, at) + ": " + message);
}

void YamlReader::expect_map(const YAML::Node& node, std::string_view what) const {
  if (!node.IsMap()) fail(node, std::string(what) + " must be a mapping of keys to values");
}

void YamlReader::expect_sequence(const YAML::Node& node, std::string_view what) const {
  if (!node.IsSequence()) fail(node, std::string(what) + " must be a list");
}

void YamlReader::allow_keys(const YAML::Node& map, std::initializer_list<std::string_view> allowed) const {
  std::set<std::string> seen;
  for (const auto& entry : map) {
    const std::string key = entry.first.Scalar();
    if (!seen.insert(key).second) fail(entry.first, "key '" + key + "' appears twice");
    bool known = false;
    for (auto a : allowed) known = known || key == a;
    if (known) continue;
    std::string list;
    for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    fail(entry.first, "unknown key '" + key + "' (expected one of: " + list + ")");
  }
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& key) const {
  YAML::Node child = map[key];
  if (!child) fail(map, "missing key '" + key + "'");
  return child;
}

double YamlReader::number(const YAML::Node& node, std::string_view what) const {
  double value = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value))
    fail(node, std::string(what) + " must be a finite number, got '" +
                   (node.IsScalar() ? node.Scalar() : std::string("non-scalar")) + "'");
  return value;
}

double YamlReader::number_in(const YAML::Node& node, std::string_view what, double lo, double hi) const {
  const double value = number(node, what);
  if (value < lo || value > hi) {
    std::ostringstream msg;
    msg << what << " = " << value << " is out of range [" << lo << ", " << hi << "]";
    fail(node, msg.str());
  }
  return value;
}

void YamlReader::read_number(const YAML::Node& map, const char* key, double& value, double lo, double hi) const {
  if (const YAML::Node n = map[key]) value = number_in(n, key, lo, hi);
}

long YamlReader::integer_in(const YAML::Node& node, std::string_view what, long lo, long hi) const {
  long value = 0;
  if (!node.IsScalar() || !YAML::convert<long>::decode(node, value))
    fail(node, std::string(what) + " must be an integer");
  if (value < lo || value > hi)
    fail(node, std::string(what) + " = " + std::to_string(value) + " is out of range [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]");
  return value;
}

bool YamlReader::boolean(const YAML::Node& node, std::string_view what) const {
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
    fail(node, std::string(what) + " must be true or false");
  return value;
}

std::string YamlReader::string(const YAML::Node& node, std::string_view what) const {
  if (!node.IsScalar()) fail(node, std::string(what) + " must be a string");
  return node.Scalar();
}

Eigen::Vector2d YamlReader::vec2(const YAML::Node& node, std::string_view what) const {
  if (!node.IsSequence() || node.size() != 2) fail(node, std::string(what) + " must be [x, y]");
  return {number(node[0], what), number(node[1], what)};
}

Eigen::Vector3d YamlReader::vec3(const YAML::Node& node, std::string_view what) const {
  if (!node.IsSequence() || node.size() != 3) fail(node, std::string(what) + " must be [x, y, z]");
  return {number(node[0], what), number(node[1], what), number(node[2], what)};
}

}  // namespace lidarloop
