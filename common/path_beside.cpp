#include "common/path_beside.hpp"

#include <filesystem>

namespace lidarloop {

std::string path_beside(const std::string& file, const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path), folder = fs::path(file).parent_path();
  if (p.is_absolute() || folder.empty()) return path;
  return (folder / p).lexically_normal().string();
}

}  // namespace lidarloop
