// lidarloop world: build a world and export its mesh and curb map.
#include <chrono>
#include <iostream>

#include "sim/lanelet2_world.hpp"
#include "sim/obj_file.hpp"
#include "sim/opendrive_world.hpp"
#include "sim/world_assets.hpp"
#include "tools/commands.hpp"
#include "tools/world_map_png.hpp"

namespace lidarloop {

static int run_world(const Args& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const LoadedWorld w = load_world(args.positional().at(0));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  double curb_length = 0;
  for (const auto& c : w.world.curbs)
    for (size_t i = 1; i < c.size(); ++i) curb_length += (c[i] - c[i - 1]).norm();
  const auto size = w.world.bounds.sizes();
  std::cout << "world        " << w.world.name << " (" << w.description.file << ")\n"
            << "origin       " << w.world.origin.lat_deg << ", " << w.world.origin.lon_deg << " (WGS-84)\n"
            << "extent       " << size.x() << " m x " << size.y() << " m\n"
            << (w.description.lanelet2 ? "lanelets     " + std::to_string(w.description.lanelet2->map.lanelets.size())
                : w.description.opendrive ? "roads        " + std::to_string(w.description.opendrive->map.roads.size())
                                          : "roads        " + std::to_string(w.description.roads.size()))
            << "\n"
            << "curb lines   " << w.world.curbs.size() << " (" << curb_length << " m)\n"
            << "triangles    " << w.world.mesh.triangle_count() << "\n"
            << "built in     " << ms << " ms\n";
  if (!w.world.import_report.empty()) std::cout << w.world.import_report;
  if (auto obj = args.value("obj")) {
    write_obj(*obj, w.world.mesh, w.materials);
    std::cout << "mesh         " << *obj << "\n";
  }
  if (auto png = args.value("png")) {
    const double resolution = args.number("resolution", 0.25);
    if (resolution < 0.02 || resolution > 10) throw InputError("--resolution must be 0.02 to 10 m per pixel");
    write_world_map_png(*png, w.world, w.materials, resolution);
    std::cout << "picture      " << *png << "\n";
  }
  if (auto curbs = args.value("curbs")) {
    write_curb_map(*curbs, w.world.curb_map());
    std::cout << "curb map     " << *curbs << "\n";
  }
  return 0;
}

Command world_command() {
  return {{"world",
           "lidarloop world WORLD|MAP.osm|MAP.xodr [--obj FILE.obj] [--curbs FILE.geojson] [--png FILE.png]",
           "Build a world (a name under maps/, a world.yaml path, a Lanelet2 map's .osm or an OpenDRIVE map's\n"
           ".xodr); print its size and\n"
           "what it is made of, export mesh and curbs.",
           {{"obj", "FILE", "write the triangle mesh as Wavefront OBJ (one usemtl group per material)"},
            {"curbs", "FILE", "write the curb map as GeoJSON LineStrings in WGS-84"},
            {"png", "FILE", "write a top view coloured by material, curb lines by kind (with a key)"},
            {"resolution", "M", "metres per pixel of the top view (default 0.25)"}},
           1,
           1},
          run_world};
}

}  // namespace lidarloop
