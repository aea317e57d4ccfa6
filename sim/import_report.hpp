#pragma once
// The closing lines of a world-from-a-map build report (sim/lanelet2_world.hpp,
// sim/opendrive_world.hpp): what was not built, by kind, and the warnings, one line each.
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace lidarloop {

inline void write_not_built(std::ostream& o, const std::map<std::string, int>& not_built,
                            const std::vector<std::string>& warnings) {
  if (!not_built.empty()) {
    o << "not built:";
    for (const auto& [k, n] : not_built) o << " " << k << ": " << n << ";";
    o << "\n";
  }
  for (const auto& w : warnings) o << "warning: " << w << "\n";
}

}  // namespace lidarloop
