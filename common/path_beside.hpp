#pragma once
// Paths written inside a file (a scenario's world, a world's map, a sweep's base scenario) mean the same
// whatever folder the program was started in: a relative one is taken from the folder of the file
// that names it.
#include <string>

namespace lidarloop {

// `path` as named in `file`: unchanged when absolute or when `file` has no folder, else joined to
// `file`'s folder (lexically normalised, so "a/../b" stays readable in messages).
std::string path_beside(const std::string& file, const std::string& path);

}  // namespace lidarloop
