// `avrbench fuzz` (bench/tools/FuzzCommand.cpp): the command line; the
// campaign itself is fuzz/campaign/FuzzCampaign.hpp.
#pragma once

#include <string>
#include <vector>

namespace avrbench {

struct FuzzArgs {
    std::string elf;
    std::string board;
    std::string duration = "60s";  // wall-clock time of the campaign (with --runs: its guard)
    unsigned long runs = 0;        // executions of the campaign (0: until --for ends)
    std::string runs_text;         // --runs as given (checked: 1 to 10^12)
    std::string bound = "5s";      // simulated time one input may take
    std::string out = "fuzz-out";
    std::string family;  // "" = the board's
    std::string corpus;  // a directory of seed inputs, or ""
    std::vector<std::string> firmware;  // "mcu=elf" for a multi-MCU board's other MCUs serial port's
    bool raw = false;             // bytes straight to the port (binary protocols)
    bool hang = false;            // a line unanswered when the bound ends is a finding
    unsigned long long steady = 100000;  // instructions an input may only repeat itself (0: to the bound)
    std::string boot = "0.2s";    // raw: simulated time the firmware boots before the first input
    std::string engine = "libfuzzer";  // or "afl"
    int jobs = 1;                 // 1 to 64
    unsigned seed = 1;
    // --replay FILE: run one input as the campaign's target ran it (no
    // campaign), under avr-gdb with `debug.gdb`.
    std::string replay;
    std::vector<std::string> gdb;
    bool break_at_finding = false;
    std::string break_at, break_at_cycle;
};

// Exit 0: nothing found; 1: findings (listed); BadInput for bad arguments.
int fuzz_command(const FuzzArgs& args);

}  // namespace avrbench
