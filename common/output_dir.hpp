#pragma once
// The folder a command writes its files into.
#include <string>

namespace lidarloop {

// Creates `dir` (and its parents) for a command's output files and checks that files can be made in
// it: called before a run, so that an output that cannot be written fails at once, not after the run.
// InputError naming the folder and the reason otherwise.
void prepare_output_dir(const std::string& dir);

}  // namespace lidarloop
