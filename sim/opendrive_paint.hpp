#pragma once
// Paint from an OpenDRIVE map: every lane's road marks along its outer edge (the centre lane's along
// the offset reference line) with their widths and patterns, and crosswalk objects' stripes. The
// rules, and the sources of the defaults, are in sim/opendrive_world.hpp.
#include <functional>

#include "sim/opendrive_world.hpp"

namespace lidarloop {

// `ground` is the height paint lies on (the pavement, else the raised ground).
void paint_opendrive(const OdrMap& map, const OdrWorldParams& params,
                     const std::function<double(const Eigen::Vector2d&)>& ground, MaterialId lane_paint,
                     MaterialId crosswalk_paint, TriangleMesh& mesh, OdrBuildReport& report, MarkingPainter& painter);

// The outline of an object in the map's x / y: its outline's corners (road or local frame), else its
// length x width box; empty when it has neither.
Polyline2d object_outline(const OdrRoad& road, const OdrObject& object);

}  // namespace lidarloop
