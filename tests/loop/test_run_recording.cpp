// The vehicle a log carries (run_recording.hpp's kVehicleAttachment) reads back through the same
// strict reader as assets/vehicle.yaml, every number exactly.
#include <gtest/gtest.h>

#include <cstring>

#include "loop/run_recording.hpp"

namespace lidarloop {
namespace {

VehicleParams read_back(const std::string& text) {
  const YamlReader y = YamlReader::from_string(text, "vehicle.yaml");
  VehicleParams v;
  read_vehicle_params(y, y.root(), v);
  return v;
}

TEST(RecordedVehicle, EveryFieldReadsBackExactly) {
  VehicleParams v;  // every field off its default, with digits no short decimal holds
  v.cornering_stiffness_front = 51234.56789012345;
  v.cornering_stiffness_rear = 60000.0 / 7.0;
  v.lf = 1.0 / 3.0;
  v.lr = 2.0 / 3.0 + 1.0;
  v.yaw_inertia = 6543.21;
  v.mass = 1999.999;
  v.steering_ratio = 15.1 + 1e-12;
  v.wheel_radius = 0.3123;
  v.track_width = 1.55;
  v.max_steer = 0.6;
  v.max_steer_rate = 0.45;
  v.steer_time_constant = 0.0;
  v.max_accel = 3.25;
  v.max_decel = 7.5;
  v.accel_time_constant = 0.3;
  v.max_speed = 20.0;
  v.kinematic_below = 2.0;
  v.step_ns = 500'000;
  const VehicleParams back = read_back(vehicle_yaml(v));
  static_assert(sizeof(VehicleParams) == 18 * 8, "a field was added: set it above and in vehicle_yaml");
  EXPECT_EQ(std::memcmp(&back, &v, sizeof v), 0) << vehicle_yaml(v) << "\nread back as\n" << vehicle_yaml(back);
  EXPECT_EQ(vehicle_yaml(back), vehicle_yaml(v));
}

}  // namespace
}  // namespace lidarloop
