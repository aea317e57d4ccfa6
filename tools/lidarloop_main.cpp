// lidarloop: the command-line front end. Exit codes: 0 success, 1 a scenario failed its thresholds,
// 2 bad input or usage, or an output that cannot be written (a missing or read-only folder, a full
// disk), 3 an internal error.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

#include "common/input_error.hpp"
#include "tools/commands.hpp"

using namespace lidarloop;

static std::vector<Command> commands() {
  return {world_command(),   scan_command(),    validate_command(), simulate_command(), run_command(),
          compare_command(), replay_command(),  score_command(),    map_command(),      info_command(),
          export_command(),  recover_command(), odometry_command(), bench_command(),    sweep_command()};
}

// A command's first sentence, its lines joined: the summary's opening sentence says what the command
// does, the rest how.
static std::string first_sentence(const std::string& summary) {
  std::string text = summary;
  std::replace(text.begin(), text.end(), '\n', ' ');
  const size_t end = text.find(". ");
  return end == std::string::npos ? text : text.substr(0, end + 1);
}

static void print_usage(std::ostream& out) {
  constexpr size_t kIndent = 12, kWidth = 100;  // a table of contents that fits a terminal
  out << "usage: lidarloop <command> [options]   (lidarloop <command> --help for details)\n\ncommands:\n";
  for (const auto& c : commands()) {
    std::string line = "  " + c.spec.name;
    line.resize(kIndent, ' ');
    std::istringstream words(first_sentence(c.spec.summary));
    std::string word;
    size_t column = kIndent;
    while (words >> word) {
      if (column > kIndent && column + 1 + word.size() > kWidth) {
        out << line << "\n";
        line.assign(kIndent, ' ');
        column = kIndent;
      }
      if (column > kIndent) line += ' ', ++column;
      line += word;
      column += word.size();
    }
    out << line << "\n";
  }
}

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(std::cout);
    return 0;
  }
  for (const auto& c : commands()) {
    if (c.spec.name != name) continue;
    try {
      const Args args = parse_args(c.spec, std::vector<std::string>(argv + 2, argv + argc));
      if (args.flag("help")) {
        std::cout << help(c.spec);
        return 0;
      }
      return c.run(args);
    } catch (const InputError& e) {
      std::cerr << "lidarloop: error: " << e.what() << "\n";
      return 2;
    } catch (const std::filesystem::filesystem_error& e) {
      // A folder or file the command was told to use and cannot: the user's to fix, like bad input.
      const std::string path = e.path1().empty() ? std::string("file system") : e.path1().string();
      std::cerr << "lidarloop: error: " << path << ": " << e.code().message() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "lidarloop: internal error: " << e.what() << "\n";
      return 3;
    }
  }
  std::cerr << "lidarloop: error: unknown command '" << name << "'\n";
  print_usage(std::cerr);
  return 2;
}
