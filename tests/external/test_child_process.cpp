// Talking to another program over pipes with deadlines: lines back, and every way it can fail to
// answer (too slow, exits, stops reading) reported instead of hanging.
#include <gtest/gtest.h>

#include <chrono>

#include "common/input_error.hpp"
#include "external/child_process.hpp"

namespace lidarloop {
namespace {

using Clock = ChildProcess::Clock;
using namespace std::chrono_literals;

std::span<const uint8_t> bytes(const std::string& s) { return {reinterpret_cast<const uint8_t*>(s.data()), s.size()}; }

TEST(ChildProcess, SendsBytesAndReadsLinesBack) {
  ChildProcess child({"sh", "-c", "while read line; do echo \"got $line\"; done"});
  std::string line;
  for (const char* word : {"one", "two"}) {
    child.send(bytes(std::string(word) + "\n"));
    ASSERT_EQ(child.read_line(Clock::now() + 5s, line), ChildProcess::LineStatus::line);
    EXPECT_EQ(line, std::string("got ") + word);
  }
  EXPECT_TRUE(child.close_stdin(Clock::now() + 5s));
  const auto status = child.wait_exit(Clock::now() + 5s);
  ASSERT_TRUE(status);
  EXPECT_EQ(describe_wait_status(*status), "exited with status 0");
}

TEST(ChildProcess, AProgramThatNeitherReadsNorAnswersTimesOut) {
  ChildProcess child({"sleep", "30"});
  child.send(std::vector<uint8_t>(8 << 20, 'x'));  // far more than a pipe holds
  const auto start = Clock::now();
  std::string line;
  EXPECT_EQ(child.read_line(start + 100ms, line), ChildProcess::LineStatus::timed_out);
  EXPECT_LT(Clock::now() - start, 5s);
  child.kill();
  const auto status = child.wait_exit(Clock::now());
  ASSERT_TRUE(status);
  EXPECT_EQ(describe_wait_status(*status), "killed by signal 9 (Killed)");
}

TEST(ChildProcess, AProgramThatExitsEndsItsOutput) {
  ChildProcess child({"sh", "-c", "printf partial; exit 3"});
  std::string line;
  EXPECT_EQ(child.read_line(Clock::now() + 5s, line), ChildProcess::LineStatus::closed);
  EXPECT_EQ(child.unread_output(), "partial");
  const auto status = child.wait_exit(Clock::now() + 5s);
  ASSERT_TRUE(status);
  EXPECT_EQ(describe_wait_status(*status), "exited with status 3");
}

TEST(ChildProcess, WritingToAProgramThatStoppedReadingIsReportedNotFatal) {
  // Without care, the write would raise SIGPIPE and kill the test process.
  ChildProcess child({"sh", "-c", "exec 0<&-; sleep 30"});
  child.send(std::vector<uint8_t>(8 << 20, 'x'));  // more than the pipe holds, whenever it closes stdin
  std::string line;
  EXPECT_EQ(child.read_line(Clock::now() + 5s, line), ChildProcess::LineStatus::stdin_closed);
}

TEST(ChildProcess, AnOverlongLineIsRefused) {
  ChildProcess child({"sh", "-c", "head -c 200000 /dev/zero | tr '\\\\0' x; echo"});
  std::string line;
  EXPECT_EQ(child.read_line(Clock::now() + 5s, line, 1 << 16), ChildProcess::LineStatus::too_long);
}

TEST(ChildProcess, AMissingProgramIsAnInputError) {
  try {
    ChildProcess child({"/no/such/program"});
    FAIL() << "started a missing program";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/program: cannot start the program (No such file or directory)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace lidarloop
