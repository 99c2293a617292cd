// A usage error's hint: the option or subcommand the user most likely meant
// (`--gcod` -> `--gcode`, `runn` -> `run`), found by edit distance among the
// names the command line knows.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace avrbench {

// "; did you mean --gcode?" or "" when nothing is near enough.
std::string usage_hint(CLI::App& app, int argc, char** argv);

}  // namespace avrbench
