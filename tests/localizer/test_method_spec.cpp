// Methods as scenarios and the command line name them: built-in names and `exec:PROGRAM ARGS`, the
// command line's words, and the labels tables and folders use.
#include <gtest/gtest.h>

#include <stdexcept>

#include "common/input_error.hpp"
#include "localizer/localizer_params.hpp"

namespace lidarloop {
namespace {

using Words = std::vector<std::string>;

TEST(CommandLine, SplitsAsAShellWouldWithoutExpanding) {
  EXPECT_EQ(split_command_line("node  localizer.mjs --record out.mcap"),
            (Words{"node", "localizer.mjs", "--record", "out.mcap"}));
  EXPECT_EQ(split_command_line("prog 'two words' \"say \\\"hi\\\"\" a\\ b ''"),
            (Words{"prog", "two words", "say \"hi\"", "a b", ""}));
  EXPECT_EQ(split_command_line("echo $HOME *"), (Words{"echo", "$HOME", "*"}));
  EXPECT_THROW(split_command_line("prog 'open"), std::invalid_argument);
  EXPECT_THROW(split_command_line("prog \\"), std::invalid_argument);
}

TEST(MethodSpec, ExecTakesACommandAndABuiltInNameClearsIt) {
  LocalizerParams p;
  set_method(p, "exec:./my localizer' 'v2 --fast");
  EXPECT_EQ(p.external.command, (Words{"./my", "localizer v2", "--fast"}));
  EXPECT_EQ(method_label(p), "exec-my-localizer_v2");
  // The text round-trips through set_method, quoting included.
  LocalizerParams again;
  set_method(again, method_text(p));
  EXPECT_EQ(again.external.command, p.external.command);
  set_method(p, "icp");
  EXPECT_TRUE(p.external.command.empty());
  EXPECT_EQ(p.method, LocalizerMethod::icp);
  EXPECT_EQ(method_label(p), "icp");
  EXPECT_EQ(method_label("exec:/usr/bin/node /opt/loc.mjs --x 1"), "exec-node-loc.mjs");
  EXPECT_THROW(set_method(p, "exec:   "), std::invalid_argument);
  EXPECT_THROW(set_method(p, "magic"), std::invalid_argument);
}

TEST(MethodSpec, ScenarioYamlSetsTheProgramAndItsDeadlines) {
  const YamlReader y = YamlReader::from_string(
      "localizer:\n  method: \"exec:prog --flag\"\n  external: {deadline_ms: 50, startup_timeout_s: 3}\n", "s.yaml");
  LocalizerParams p;
  read_localizer_params(y, y.root()["localizer"], p);
  EXPECT_EQ(p.external.command, (Words{"prog", "--flag"}));
  EXPECT_EQ(p.external.deadline_ms, 50);
  EXPECT_EQ(p.external.startup_timeout_s, 3);
  const YamlReader bad = YamlReader::from_string("localizer:\n  external: {deadline: 50}\n", "bad.yaml");
  try {
    read_localizer_params(bad, bad.root()["localizer"], p);
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2:14: unknown key 'deadline'"), std::string::npos) << e.what();
  }
}

TEST(MethodSpec, LatencyIsOneScanMeasuredOrMilliseconds) {
  EXPECT_EQ(parse_latency("one_scan").model, LatencyModel::one_scan);
  EXPECT_EQ(parse_latency("measured").model, LatencyModel::measured);
  const LatencyParams fixed = parse_latency("80");
  EXPECT_EQ(fixed.model, LatencyModel::fixed);
  EXPECT_EQ(fixed.fixed_ms, 80);
  EXPECT_EQ(latency_text(fixed), "80 ms");
  for (const char* bad : {"", "-1", "fast", "80ms", "60001", "nan"})
    EXPECT_THROW(parse_latency(bad), std::invalid_argument) << bad;

  const YamlReader y = YamlReader::from_string("localizer: {latency: 12.5}\n", "s.yaml");
  LocalizerParams p;
  EXPECT_EQ(p.latency.model, LatencyModel::automatic);
  read_localizer_params(y, y.root()["localizer"], p);
  EXPECT_EQ(p.latency.model, LatencyModel::fixed);
  EXPECT_EQ(p.latency.fixed_ms, 12.5);
  const YamlReader bad = YamlReader::from_string("localizer: {latency: soon}\n", "bad.yaml");
  try {
    read_localizer_params(bad, bad.root()["localizer"], p);
    FAIL() << "a bad latency was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:1:22: latency 'soon'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lidarloop
