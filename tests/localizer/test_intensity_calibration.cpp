// Each laser's intensity response, learned against the map: a known gain and offset are recovered, a
// laser that sees one surface only keeps its gain near one, and correct() undoes the response.
#include <gtest/gtest.h>

#include <random>

#include "localizer/intensity_calibration.hpp"

namespace lidarloop {
namespace {

TEST(IntensityCalibration, RecoversEachLasersGainAndOffset) {
  IntensityCalibration c;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> surface(5, 60);  // asphalt to paint, counts
  std::normal_distribution<double> noise(0, 1.5);
  const double gain[2] = {1.12, 0.9}, offset[2] = {2.0, -3.0};
  for (int scan = 0; scan < 50; ++scan) {
    for (int k = 0; k < 500; ++k)
      for (int ring = 0; ring < 2; ++ring) {
        const double x = surface(rng);
        c.add(ring, gain[ring] * x + offset[ring] + noise(rng), x);
      }
    c.end_scan();
  }
  for (int ring = 0; ring < 2; ++ring) {
    EXPECT_NEAR(c.gain(ring), gain[ring], 0.01) << ring;
    EXPECT_NEAR(c.offset(ring), offset[ring], 0.3) << ring;
    EXPECT_NEAR(c.correct(ring, gain[ring] * 30 + offset[ring]), 30.0, 0.3) << ring;
  }
  EXPECT_DOUBLE_EQ(c.correct(7, 20), 20);  // a laser never seen reads as it is
}

TEST(IntensityCalibration, ALaserThatSeesOnlyAsphaltLearnsItsOffsetNotAWildGain) {
  IntensityCalibration c;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 1.5);
  for (int scan = 0; scan < 100; ++scan) {
    for (int k = 0; k < 300; ++k) c.add(0, 10 + 2.0 + noise(rng), 10);  // reads 2 counts high on asphalt
    c.end_scan();
  }
  EXPECT_NEAR(c.correct(0, 12), 10, 0.2);  // asphalt put back on the map's scale
  EXPECT_GT(c.gain(0), 0.8);               // the prior's bright returns keep the slope sane
  EXPECT_LT(c.gain(0), 1.1);
}

TEST(IntensityCalibration, DisabledLeavesReadingsAlone) {
  IntensityCalibrationParams p;
  p.enabled = false;
  IntensityCalibration c(p);
  for (int k = 0; k < 1000; ++k) c.add(0, 20, 10);
  c.end_scan();
  EXPECT_DOUBLE_EQ(c.correct(0, 20), 20);
}

}  // namespace
}  // namespace lidarloop
