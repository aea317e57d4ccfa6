#include "common/yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "common/units.hpp"

namespace lidarloop {
namespace {

// Edits (insertions, deletions, substitutions) that turn a into b: Levenshtein's distance.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// A misspelling is one edit from a short word, two from a longer one: "lat" and "lon" are two
// different words, "lanez" and "lanes" one.
bool looks_misspelt(const std::string& written, const std::string& meant) {
  return edit_distance(written, meant) <= (meant.size() <= 4 ? 1u : 2u);
}

}  // namespace

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

YamlMap::YamlMap(const YamlReader& reader, const YAML::Node& node, std::string_view what)
    : reader_(reader), node_(node) {
  if (present()) reader_.expect_map(node_, what);
}

YAML::Node YamlMap::operator[](const char* key) {
  keys_.emplace_back(key);
  if (!present()) return YAML::Node(YAML::NodeType::Undefined);
  return static_cast<const YAML::Node&>(node_)[key];  // the const lookup: never inserts the key
}

YAML::Node YamlMap::required(const char* key) {
  const YAML::Node child = (*this)[key];
  if (child) return child;
  // A key missing beside a misspelling of it is reported at the misspelling, where the fix is.
  if (present())
    for (const auto& entry : node_)
      if (looks_misspelt(entry.first.Scalar(), key))
        reader_.fail(entry.first, "unknown key '" + entry.first.Scalar() + "' (did you mean '" + key + "'?)");
  reader_.fail(node_, "missing key '" + std::string(key) + "'");
}

YamlMap& YamlMap::number(const char* key, double& value, double lo, double hi) {
  if (const YAML::Node n = (*this)[key]) value = reader_.number_in(n, key, lo, hi);
  return *this;
}

YamlMap& YamlMap::number(const char* key, std::optional<double>& value, double lo, double hi) {
  if (const YAML::Node n = (*this)[key]) value = reader_.number_in(n, key, lo, hi);
  return *this;
}

YamlMap& YamlMap::degrees(const char* key, double& radians, double lo_deg, double hi_deg) {
  if (const YAML::Node n = (*this)[key]) radians = reader_.number_in(n, key, lo_deg, hi_deg) * kDeg;
  return *this;
}

YamlMap& YamlMap::integer(const char* key, int& value, int lo, int hi) {
  if (const YAML::Node n = (*this)[key]) value = int(reader_.integer_in(n, key, lo, hi));
  return *this;
}

YamlMap& YamlMap::integer(const char* key, int64_t& value, int64_t lo, int64_t hi) {
  if (const YAML::Node n = (*this)[key]) value = reader_.integer_in(n, key, lo, hi);
  return *this;
}

YamlMap& YamlMap::integer(const char* key, uint64_t& value, uint64_t lo, uint64_t hi) {
  if (const YAML::Node n = (*this)[key]) value = uint64_t(reader_.integer_in(n, key, long(lo), long(hi)));
  return *this;
}

YamlMap& YamlMap::boolean(const char* key, bool& value) {
  if (const YAML::Node n = (*this)[key]) value = reader_.boolean(n, key);
  return *this;
}

YamlMap& YamlMap::string(const char* key, std::string& value) {
  if (const YAML::Node n = (*this)[key]) value = reader_.string(n, key);
  return *this;
}

YamlMap& YamlMap::vec2(const char* key, Eigen::Vector2d& value) {
  if (const YAML::Node n = (*this)[key]) value = reader_.vec2(n, key);
  return *this;
}

YamlMap& YamlMap::vec3(const char* key, Eigen::Vector3d& value) {
  if (const YAML::Node n = (*this)[key]) value = reader_.vec3(n, key);
  return *this;
}

void YamlMap::done() const {
  if (!present()) return;
  std::set<std::string> seen;
  for (const auto& entry : node_) {
    const std::string key = entry.first.Scalar();
    if (!seen.insert(key).second) reader_.fail(entry.first, "key '" + key + "' appears twice");
    if (std::find(keys_.begin(), keys_.end(), key) != keys_.end()) continue;
    std::string list, nearest;
    for (const auto& k : std::set<std::string>(keys_.begin(), keys_.end())) {
      list += (list.empty() ? "" : ", ") + k;
      if (nearest.empty() && looks_misspelt(key, k)) nearest = k;
    }
    const std::string hint = nearest.empty() ? "" : "did you mean '" + nearest + "'? ";
    reader_.fail(entry.first, "unknown key '" + key + "' (" + hint + "expected one of: " + list + ")");
  }
}

}  // namespace lidarloop
