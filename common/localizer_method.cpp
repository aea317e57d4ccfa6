#include "common/localizer_method.hpp"

#include <stdexcept>

namespace lidarloop {

const std::vector<std::string>& localizer_method_names() {
  static const std::vector<std::string> names = {"gps", "icp",       "icp-obs",  "m-icp",
                                                 "fmt", "intensity", "proposed", "gicp"};
  return names;
}

std::string method_name(LocalizerMethod m) { return localizer_method_names()[size_t(m)]; }

std::string method_name_list() {
  std::string list;
  for (const auto& n : localizer_method_names()) list += (list.empty() ? "" : ", ") + n;
  return list;
}

LocalizerMethod parse_localizer_method(const std::string& name) {
  const auto& names = localizer_method_names();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return LocalizerMethod(i);
  throw std::invalid_argument("unknown localizer method '" + name + "' (expected one of: " + method_name_list() + ")");
}

}  // namespace lidarloop
