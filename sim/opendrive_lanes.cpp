#include "sim/opendrive_lanes.hpp"

#include <algorithm>
#include <cmath>

#include "sim/opendrive_geometry.hpp"
#include "sim/polyline.hpp"

namespace lidarloop {

std::vector<OdrLanePath> opendrive_driving_paths(const OdrMap& map, double step) {
  std::vector<OdrLanePath> out;
  for (const auto& road : map.roads) {
    if (road.junction != "-1") continue;
    // Lane ids that drive in any section; a path runs while consecutive sections have that lane driving.
    std::vector<int> ids;
    for (const auto& sec : road.sections)
      for (const auto* side : {&sec.left, &sec.right})
        for (const auto& lane : *side)
          if (lane.type == "driving" && std::find(ids.begin(), ids.end(), lane.id) == ids.end()) ids.push_back(lane.id);
    for (const int id : ids) {
      OdrLanePath path{road.id, id, {}};
      auto flush = [&] {
        if (path.centreline.size() >= 2) {
          if (id > 0) std::reverse(path.centreline.begin(), path.centreline.end());
          out.push_back(path);
        }
        path.centreline.clear();
      };
      for (size_t i = 0; i < road.sections.size(); ++i) {
        const OdrLane* lane = road.sections[i].lane(id);
        if (!lane || lane->type != "driving") {
          flush();
          continue;
        }
        const double s0 = road.sections[i].s, s1 = std::min(road.section_end(i), road.length);
        const int n = std::max(1, int(std::ceil((s1 - s0) / step)));
        for (int k = 0; k <= n; ++k) {
          const double s = s0 + (s1 - s0) * k / n;
          const OdrLaneEdges e = lane_edges(road, i, id, s);
          const Eigen::Vector2d p = road_point(road, s, 0.5 * (e.inner + e.outer)).head<2>();
          if (path.centreline.empty() || (p - path.centreline.back()).norm() > 1e-6) path.centreline.push_back(p);
        }
      }
      flush();
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const OdrLanePath& a, const OdrLanePath& b) {
    return polyline_length(a.centreline) > polyline_length(b.centreline);
  });
  return out;
}

}  // namespace lidarloop
