#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "common/yaml_path.hpp"

using namespace lidarloop;

TEST(YamlPath, SplitsKeysAndIndexes) {
  const auto steps = parse_yaml_path("traffic[2].waits[0].at");
  ASSERT_EQ(steps.size(), 5u);
  EXPECT_EQ(std::get<std::string>(steps[0]), "traffic");
  EXPECT_EQ(std::get<size_t>(steps[1]), 2u);
  EXPECT_EQ(std::get<std::string>(steps[2]), "waits");
  EXPECT_EQ(std::get<size_t>(steps[3]), 0u);
  EXPECT_EQ(std::get<std::string>(steps[4]), "at");
}

TEST(YamlPath, RejectsMalformedPaths) {
  for (const char* bad : {"", ".a", "a..b", "a[", "a[x]", "a[]", "a]b", "a[0]b"})
    EXPECT_THROW(parse_yaml_path(bad), InputError) << bad;
}

TEST(YamlPath, SetsAValueInPlaceAndCreatesMissingMappings) {
  YAML::Node doc = YAML::Load("traffic:\n  - {type: bus, path: {offset: -2.6}}\n");
  YAML::Node offset = yaml_node_at(doc, "traffic[0].path.offset");
  offset = -1.5;
  YAML::Node zone = yaml_node_at(doc, "gps.outage_s");
  zone = 30;
  EXPECT_DOUBLE_EQ(doc["traffic"][0]["path"]["offset"].as<double>(), -1.5);
  EXPECT_EQ(doc["traffic"][0]["type"].as<std::string>(), "bus");
  EXPECT_EQ(doc["gps"]["outage_s"].as<int>(), 30);
}

TEST(YamlPath, NamesTheStepThatDoesNotFit) {
  YAML::Node doc = YAML::Load("traffic:\n  - {type: bus}\nseed: 3\n");
  try {
    yaml_node_at(doc, "traffic[1].type");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'traffic' has 1 entries, no [1]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(yaml_node_at(doc, "seed.value"), InputError);
  EXPECT_THROW(yaml_node_at(doc, "traffic.type"), InputError);
}
