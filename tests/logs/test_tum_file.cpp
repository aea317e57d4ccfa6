// TUM trajectories: written so that every number reads back as the same double and every stamp as
// the same nanosecond, and read strictly (each bad line named by its number).
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "common/input_error.hpp"
#include "logs/ros2_messages.hpp"
#include "logs/tum_file.hpp"

namespace lidarloop {
namespace {

TEST(TumFile, SecondsAreExactNanoseconds) {
  EXPECT_EQ(tum_seconds(1'500'000'000), "1.500000000");
  EXPECT_EQ(tum_seconds(-1'500'000'001), "-1.500000001");
  EXPECT_EQ(tum_seconds(7), "0.000000007");
  int64_t ns = 0;
  for (const int64_t t : {int64_t(0), int64_t(7), int64_t(123'456'789'012), int64_t(-1'500'000'001)}) {
    ASSERT_TRUE(parse_tum_seconds(tum_seconds(t), ns));
    EXPECT_EQ(ns, t);
  }
  ASSERT_TRUE(parse_tum_seconds("12.5", ns));
  EXPECT_EQ(ns, 12'500'000'000);
  ASSERT_TRUE(parse_tum_seconds("1403636580.838555527", ns));  // EuRoC-like: exact beyond a double's digits
  EXPECT_EQ(ns, 1'403'636'580'838'555'527);
  ASSERT_TRUE(parse_tum_seconds("1.25e1", ns));  // not plain decimal: through a double
  EXPECT_EQ(ns, 12'500'000'000);
  ASSERT_TRUE(parse_tum_seconds("0.1234567891", ns));  // ten digits: rounded to the nanosecond
  EXPECT_EQ(ns, 123'456'789);
  for (const char* bad : {"", "abc", "1.5x", "nan", "inf", "1e300", "--1"})
    EXPECT_FALSE(parse_tum_seconds(bad, ns)) << bad;
}

TEST(TumFile, EveryPoseReadsBackBitForBit) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1000, 1000);
  std::string text = kTumHeader;
  std::vector<TumPose> written;
  for (int i = 0; i < 1000; ++i) {
    TumPose p;
    p.stamp_ns = int64_t(i) * 100'000'007 + 3;
    p.position = {u(rng), u(rng) * 1e-9, u(rng) * 1e7};
    p.orientation = ros2::yaw_quaternion(u(rng));
    written.push_back(p);
    text += tum_line(p) + "\n";
  }
  const std::vector<TumPose> read = parse_tum(text, "t.tum");
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].stamp_ns, written[i].stamp_ns);
    EXPECT_EQ(read[i].position, written[i].position);
    EXPECT_EQ(read[i].orientation.coeffs(), written[i].orientation.coeffs());
  }
  EXPECT_EQ(tum_line({0, {1.25, -2.5, -0.0}, Eigen::Quaterniond::Identity()}), "0.000000000 1.25 -2.5 0 0 0 0 1");
}

TEST(TumFile, YawThroughTheQuaternionIsTheOneSharedPair) {
  for (double yaw : {0.0, 0.3, -2.0, 3.14159, -3.14159}) {
    EXPECT_NEAR(ros2::published_yaw(yaw), yaw, 1e-15);
    EXPECT_EQ(ros2::published_yaw(yaw), ros2::yaw_of(ros2::yaw_quaternion(yaw)));
  }
  // A full 3-D attitude: the yaw of its ZYX angles; the quaternion's scale does not matter.
  const Eigen::Quaterniond q = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(ros2::yaw_of(q), 0.7, 1e-12);
  EXPECT_NEAR(ros2::yaw_of(Eigen::Quaterniond(q.coeffs().w() * 3, q.x() * 3, q.y() * 3, q.z() * 3)), 0.7, 1e-12);
}

TEST(TumFile, BadFilesNameTheLineAndTheProblem) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"", "t.tum: no poses"},
      {"# only a comment\n\n", "t.tum: no poses"},
      {"0 1 2 3 0 0 0 1\n1 1 2 3 0 0 0\n", "t.tum:2: expected 8 numbers (t x y z qx qy qz qw), got 7"},
      {"0 1 2 3 0 0 0 1\n1 1 nan 3 0 0 0 1\n", "t.tum:2: 'nan' is not a finite number"},
      {"0 1 2 3 0 0 0 1\n1 1 2 3 0 0 zero 1\n", "t.tum:2: 'zero' is not a finite number"},
      {"x 1 2 3 0 0 0 1\n", "t.tum:1: time stamp 'x' is not a finite number of seconds"},
      {"0 1 2 3 0 0 0 0\n", "t.tum:1: the quaternion is zero"},
      {"# header\n2 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n",
       "t.tum:3: time stamp 1.000000000 s is not after the previous line's 2.000000000 s"},
      {"1 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n", "t.tum:2: time stamp 1.000000000 s is not after"},
  };
  for (const auto& c : cases) {
    try {
      parse_tum(c.text, "t.tum");
      ADD_FAILURE() << c.message << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(c.message, 0), 0u) << e.what();
    }
  }
  // Windows line ends, tabs and a trailing comment line are fine.
  EXPECT_EQ(parse_tum("0\t1 2 3 0 0 0 1\r\n1 1 2 3 0 0 0 1\r\n# end\r\n", "t.tum").size(), 2u);
}

}  // namespace
}  // namespace lidarloop
