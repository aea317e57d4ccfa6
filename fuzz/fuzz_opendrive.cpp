// An OpenDRIVE map (.xodr) as `world` reads it (sim/opendrive_file.hpp), and the geometry the world
// builder then evaluates (sim/opendrive_geometry.hpp) along every road it accepted, so that what the
// reader lets through cannot crash or hang the evaluation either.
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "sim/opendrive_file.hpp"
#include "sim/opendrive_geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace lidarloop;
  try {
    const OdrMap map = parse_opendrive(std::string(fuzz::as_text(data, size)), "fuzz.xodr");
    for (const auto& road : map.roads)
      for (int k = 0; k <= 8; ++k) {
        const double s = road.length * k / 8;
        const size_t sec = road.section_at(s);
        for (const auto* side : {&road.sections[sec].left, &road.sections[sec].right})
          for (const auto& lane : *side)
            lane_surface_point(road, sec, lane, s, lane_edges(road, sec, lane.id, s).outer);
      }
  } catch (const InputError&) {
  }
  return 0;
}
