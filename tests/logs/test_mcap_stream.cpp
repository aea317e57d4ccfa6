// MCAP as a live stream (what an `exec:` localizer reads on its stdin): the writer's unchunked mode
// into a byte sink, and the reader on a pipe, message by message as the bytes arrive.
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "logs/log_topics.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/mcap_recorder.hpp"
#include "logs/ros2_messages.hpp"

namespace lidarloop {
namespace {

using Bytes = std::vector<uint8_t>;

McapWriterOptions stream_options() {
  McapWriterOptions o;
  o.chunked = false;
  o.compress = false;
  return o;
}

CanFrame can_frame(int64_t stamp_ns) {
  CanFrame f;
  f.stamp_ns = stamp_ns;
  f.wheel_speed_mps = {1, 2, 3, 4};
  f.steering_wheel_angle_rad = 0.25;
  return f;
}

// A pipe read through stdio, as a program's stdin is.
struct Pipe {
  Pipe() {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe");
    read_end = fdopen(fds[0], "rb");
    write_fd = fds[1];
  }
  ~Pipe() {
    if (read_end) std::fclose(read_end);
    close_write();
  }
  void write(const Bytes& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(write_fd, bytes.data() + done, bytes.size() - done);
      ASSERT_GT(n, 0);
      done += size_t(n);
    }
  }
  void close_write() {
    if (write_fd >= 0) ::close(write_fd);
    write_fd = -1;
  }
  std::FILE* read_end = nullptr;
  int write_fd = -1;
};

TEST(McapStream, EachMessageIsReadableAsSoonAsItIsWritten) {
  Bytes sent;
  // sim/gps_model.hpp's default lever arm, which an exec: program's metadata also gives.
  const Eigen::Vector3d antenna(0.9, 0.0, 1.5);
  McapRecorder recorder("test stream", [&](std::span<const uint8_t> b) { sent.insert(sent.end(), b.begin(), b.end()); },
                        Eigen::Isometry3d::Identity(), antenna, stream_options(), "lidarloop.external",
                        {{"answer", "42"}});
  recorder.flush();
  Pipe pipe;
  pipe.write(sent);
  sent.clear();
  McapReader reader(pipe.read_end, "pipe");
  McapMessage m;
  // Metadata first, then /tf_static: all there before anything else is written.
  ASSERT_TRUE(reader.next(m));
  EXPECT_EQ(m.channel->topic, log_topics::tf_static);
  const std::vector<ros2::Transform> mounts = ros2::decode_tf(m.data, "tf_static");
  ASSERT_EQ(mounts.size(), 2u);
  EXPECT_EQ(mounts[1].child, log_topics::gps_frame);
  EXPECT_EQ(mounts[1].translation, antenna);  // the fixes' lever arm, not the identity
  ASSERT_EQ(reader.metadata().size(), 1u);
  EXPECT_EQ(reader.metadata()[0].metadata.at("answer"), "42");
  // Lockstep: one message written and flushed can be read while the writer waits. A reader that
  // needed more bytes would block here for ever (and the test would time out).
  for (int i = 0; i < 3; ++i) {
    recorder.write_can(can_frame(1000 * (i + 1)));
    recorder.flush();
    pipe.write(sent);
    sent.clear();
    ASSERT_TRUE(reader.next(m));
    EXPECT_EQ(m.channel->topic, log_topics::vehicle_report);
    EXPECT_EQ(m.publish_time, uint64_t(1000 * (i + 1)));
  }
  recorder.close();
  pipe.write(sent);
  pipe.close_write();
  EXPECT_FALSE(reader.next(m));  // Data End, footer, trailing magic and the end of the stream, all checked
}

TEST(McapStream, AnUnchunkedFileIsAValidLog) {
  const std::string path = testing::TempDir() + "/unchunked_" + std::to_string(getpid()) + ".mcap";
  {
    McapRecorder recorder(path, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero(), stream_options());
    for (int i = 0; i < 5; ++i) recorder.write_can(can_frame(1000 * i));
    recorder.close();
  }
  McapReader reader(path);
  McapMessage m;
  int count = 0;
  while (reader.next(m)) count += m.channel->topic == log_topics::vehicle_report;
  EXPECT_EQ(count, 5);
  EXPECT_EQ(reader.chunks(), 0u);
  const auto summary = read_mcap_summary(path);
  ASSERT_TRUE(summary && summary->statistics);
  EXPECT_EQ(summary->statistics->message_count, 6u);  // and /tf_static
}

TEST(McapStream, AStreamCutInsideARecordIsAnInputError) {
  Bytes sent;
  McapRecorder recorder("test stream", [&](std::span<const uint8_t> b) { sent.insert(sent.end(), b.begin(), b.end()); },
                        Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero(), stream_options(), "lidarloop.external",
                        {});
  recorder.write_can(can_frame(1000));
  recorder.flush();
  Pipe pipe;
  pipe.write(Bytes(sent.begin(), sent.end() - 5));
  pipe.close_write();
  McapReader reader(pipe.read_end, "pipe");
  McapMessage m;
  ASSERT_TRUE(reader.next(m));  // /tf_static
  try {
    reader.next(m);
    FAIL() << "a cut record was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pipe: byte"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the stream ended inside a record"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lidarloop
