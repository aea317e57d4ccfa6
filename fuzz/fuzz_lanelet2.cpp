// A Lanelet2 map (.osm) as `world` reads it (sim/lanelet2_file.hpp). An input that starts with
// "projector_type" carries Autoware's map_projector_info.yaml before its first '<': both are written to
// a scratch folder and read from there, so that the local_x / local_y projections are fuzzed too.
#include <algorithm>
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "sim/lanelet2_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace lidarloop;
  const std::string_view text = fuzz::as_text(data, size);
  try {
    if (text.starts_with("projector_type")) {
      const size_t xml = std::min(text.find('<'), text.size());
      fuzz::write_bytes(fuzz::scratch_dir() / "map_projector_info.yaml", text.substr(0, xml));
      fuzz::write_bytes(fuzz::scratch_dir() / "lanelet2_map.osm", text.substr(xml));
      read_lanelet2((fuzz::scratch_dir() / "lanelet2_map.osm").string());
    } else {
      parse_lanelet2(std::string(text), "fuzz.osm");
    }
  } catch (const InputError&) {
  }
  return 0;
}
