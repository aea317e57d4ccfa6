// `lidarloop recover` on any bytes: it reports the damage it skips and throws only for a file that is
// not MCAP at all, and what it writes must always be a valid log: the strict reader reads it to the end.
#include <cstdlib>
#include <iostream>
#include <string>

#include "common/input_error.hpp"
#include "fuzz/fuzz_support.hpp"
#include "logs/mcap/mcap_reader.hpp"
#include "logs/mcap/mcap_recover.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace lidarloop;
  const std::string broken = (fuzz::scratch_dir() / "broken.mcap").string();
  const std::string fixed = (fuzz::scratch_dir() / "fixed.mcap").string();
  fuzz::write_bytes(broken, fuzz::as_text(data, size));
  McapRecoverReport report;
  try {
    report = recover_mcap(broken, fixed);
  } catch (const InputError&) {
    return 0;
  }
  try {
    McapReader reader(fixed);
    McapMessage message;
    uint64_t messages = 0;
    while (reader.next(message)) ++messages;
    if (messages != report.messages) {
      std::cerr << "recover reported " << report.messages << " messages but wrote " << messages << "\n";
      std::abort();
    }
  } catch (const InputError& e) {
    std::cerr << "recover wrote a file its reader refuses: " << e.what() << "\n";
    std::abort();
  }
  return 0;
}
