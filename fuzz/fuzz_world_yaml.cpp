// A world description (maps/*.yaml) as `world`, `map` and `run` read it.
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "sim/world_description.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace lidarloop;
  try {
    parse_world_description(std::string(fuzz::as_text(data, size)), "fuzz.yaml");
  } catch (const InputError&) {
  }
  return 0;
}
