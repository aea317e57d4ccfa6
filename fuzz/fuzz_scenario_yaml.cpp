// A scenario file as `run` reads it: the simulator's sections (parse_scenario) and the localizer's
// section with its method and parameter overrides (localizer_params_for).
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "loop/localizer_setup.hpp"
#include "sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace lidarloop;
  try {
    const Scenario scenario = parse_scenario(std::string(fuzz::as_text(data, size)), "fuzz.yaml");
    localizer_params_for(scenario);
  } catch (const InputError&) {
  }
  return 0;
}
