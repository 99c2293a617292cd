// The avrbench subcommands. Each file registers its options on the command
// line and runs through the library; main() parses and dispatches.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

#include "run/BoardRun.hpp"

namespace avrbench {

// Exit codes (docs/CLI.md).
constexpr int kExitOk = 0;
constexpr int kExitFinding = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitTimeout = 3;
constexpr int kExitInternal = 4;
constexpr int kExitInterrupted = 130;  // 128 + SIGINT

// A registered subcommand: run() is called when `command` was parsed.
struct Command {
    CLI::App* command;
    std::function<int()> run;
};

Command add_run_command(CLI::App& app);                   // RunCommand.cpp
std::vector<Command> add_check_commands(CLI::App& app);   // CheckCommand.cpp: check, golden update
std::vector<Command> add_info_commands(CLI::App& app);    // InfoCommands.cpp: boards, findings, cam
Command add_fuzz_command(CLI::App& app);                  // FuzzCommand.cpp
Command add_board_command(CLI::App& app);                 // BoardCommand.cpp: board from-config

// The exit code of a verdict, its message (if any) on stderr.
int exit_code(const RunVerdict& verdict);

}  // namespace avrbench
