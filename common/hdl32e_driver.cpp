#include "common/hdl32e_driver.hpp"

namespace lidarloop {

PointCloud hdl32e_cloud(const Hdl32eCalibration& calibration, int64_t stamp_ns, std::span<const Hdl32eBlock> blocks) {
  PointCloud cloud;
  cloud.stamp_ns = stamp_ns;
  cloud.points.reserve(blocks.size() * kHdl32eChannels);
  for (size_t cycle = 0; cycle < blocks.size(); ++cycle) {
    const Hdl32eBlock& block = blocks[cycle];
    const Hdl32eRotation2d azimuth = hdl32e_rotation(block.azimuth);
    const int64_t block_ns = int64_t(cycle) * calibration.cycle_period_ns;
    for (size_t c = 0; c < size_t(kHdl32eChannels); ++c) {
      if (block.distance[c] == 0) continue;
      const Hdl32ePoint p =
          hdl32e_point(azimuth, calibration.cos_elevation[c], calibration.sin_elevation[c], block.distance[c]);
      cloud.points.push_back({p.x, p.y, p.z, block.intensity[c], calibration.ring[c],
                              uint32_t(block_ns + int64_t(c) * calibration.firing_period_ns)});
    }
  }
  return cloud;
}

}  // namespace lidarloop
