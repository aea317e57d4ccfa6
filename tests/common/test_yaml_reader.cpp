// YamlMap, the one way the project reads a YAML mapping: the keys a reader names are the keys the
// mapping may hold, and every error names the file, line and column where the fix is.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "common/input_error.hpp"
#include "common/units.hpp"
#include "common/yaml_reader.hpp"

namespace lidarloop {
namespace {

struct Settings {
  double speed = 10;
  int lanes = 2;
  bool closed = false;
  double yaw = 0;
  std::optional<double> limit;
};

// Reads "settings.yaml" as a mapping of the keys above, with `name` required.
Settings read_settings(const std::string& text) {
  const YamlReader y = YamlReader::from_string(text, "settings.yaml");
  YamlMap m(y, y.root(), "settings");
  Settings s;
  y.string(m.required("name"), "name");
  m.number("speed", s.speed, 0.0, 40.0)
      .integer("lanes", s.lanes, 1, 8)
      .boolean("closed", s.closed)
      .degrees("yaw_deg", s.yaw, -360.0, 360.0)
      .number("limit", s.limit, 0.0, 1.0)
      .done();
  return s;
}

std::string error_of(const std::string& text) {
  try {
    read_settings(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(YamlMap, ReadsGivenKeysAndKeepsDefaultsForTheRest) {
  const Settings s = read_settings("name: a\nspeed: 12.5\nyaw_deg: 90\n");
  EXPECT_EQ(s.speed, 12.5);
  EXPECT_EQ(s.lanes, 2);
  EXPECT_FALSE(s.closed);
  EXPECT_DOUBLE_EQ(s.yaw, 90 * kDeg);
  EXPECT_FALSE(s.limit.has_value());
  EXPECT_EQ(read_settings("name: a\nlimit: 0.25\n").limit, 0.25);
}

TEST(YamlMap, AnAbsentSectionKeepsEveryDefault) {
  const YamlReader y = YamlReader::from_string("other: 1\n", "s.yaml");
  double value = 3;
  YamlMap absent(y, y.root()["section"], "section");
  EXPECT_FALSE(absent.present());
  absent.number("value", value, 0.0, 10.0).done();
  EXPECT_EQ(value, 3);
}

TEST(YamlMap, ErrorsNameTheFileLineAndColumnOfTheFix) {
  EXPECT_EQ(error_of("name: a\nsped: 3\n"),
            "settings.yaml:2:1: unknown key 'sped' (did you mean 'speed'? expected one of: closed, lanes, limit, "
            "name, speed, yaw_deg)");
  EXPECT_EQ(error_of("name: a\nwidth: 3\n"),
            "settings.yaml:2:1: unknown key 'width' (expected one of: closed, lanes, limit, name, speed, yaw_deg)");
  EXPECT_EQ(error_of("name: a\nspeed: 90\n"), "settings.yaml:2:8: speed = 90 is out of range [0, 40]");
  EXPECT_EQ(error_of("name: a\nlanes: 2.5\n"), "settings.yaml:2:8: lanes must be an integer");
  EXPECT_EQ(error_of("name: a\nclosed: maybe\n"), "settings.yaml:2:9: closed must be true or false");
  EXPECT_EQ(error_of("name: a\nspeed: 1\nspeed: 2\n"), "settings.yaml:3:1: key 'speed' appears twice");
  EXPECT_EQ(error_of("speed: 1\n"), "settings.yaml:1:1: missing key 'name'");
  EXPECT_EQ(error_of("- 1\n- 2\n"), "settings.yaml:1:1: settings must be a mapping of keys to values");
  EXPECT_EQ(error_of("name: a\nspeed: .nan\n"), "settings.yaml:2:8: speed must be a finite number, got '.nan'");
}

TEST(YamlMap, AMissingKeyBesideItsMisspellingIsReportedAtTheMisspelling) {
  EXPECT_EQ(error_of("nme: a\n"), "settings.yaml:1:1: unknown key 'nme' (did you mean 'name'?)");
  // Short words two edits apart are different words, not misspellings.
  const YamlReader y = YamlReader::from_string("lon: 8\n", "origin.yaml");
  YamlMap origin(y, y.root(), "origin");
  try {
    origin.required("lat");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "origin.yaml:1:1: missing key 'lat'");
  }
}

}  // namespace
}  // namespace lidarloop
