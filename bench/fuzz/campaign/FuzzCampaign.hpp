// A firmware fuzz campaign (`avrbench fuzz`, docs/FUZZING.md): checks the
// board and firmware, writes a seed corpus and a G-code dictionary, runs the
// engine for the given wall time or executions - Debian's libFuzzer, one job
// in one process or --jobs in its fork mode (fuzz_firmware.cpp), or Debian's
// AFL++ as one main and jobs - 1 secondary instances on a shared sync folder
// (fuzz_firmware_afl.cpp); findings do not stop the campaign - then replays
// every reproducer once to name its finding, groups them by root cause,
// minimizes one of each and records its run with `avrbench run` (summary and
// VCD). The engines run the fuzz target (fuzz/FirmwareTarget.hpp) as child
// processes: this library does not link it.
#pragma once

#include <map>
#include <string>

#include "run/BoardRun.hpp"

namespace avrbench {

struct FuzzCampaignOptions {
    std::string elf;
    std::string board;
    std::string duration = "60s";  // wall-clock time of the campaign (with runs: its guard)
    unsigned long runs = 0;        // executions of the campaign (0: until the duration ends)
    std::string bound = "5s";      // simulated time one input may take
    std::string out = "fuzz-out";  // a folder: corpus, findings, logs
    std::string family;            // "" = the board's
    std::string corpus;            // a folder of seed inputs, or ""
    std::map<std::string, std::string> firmware;  // the other MCUs of a multi-MCU board: MCU -> ELF
    bool raw = false;              // bytes straight to the port (binary protocols)
    bool hang = false;             // a line unanswered when the bound ends is a finding
    // An input that only repeats itself this many AVR instructions ends
    // (FirmwareTarget.hpp, AVRBENCH_FUZZ_STEADY); 0: every input to the bound.
    unsigned long long steady = 100000;
    std::string boot = "0.2s";     // raw: simulated time the firmware boots before the first input
    std::string engine = "libfuzzer";  // or "afl"
    int jobs = 1;                  // 1 to 64
    unsigned seed = 1;
};

// Prints the campaign's course and findings. Returns 0 when nothing was
// found, 1 with findings, 130 when stopped (Ctrl-C, SIGTERM); BadInput for a
// bad board, firmware, corpus or output folder.
int run_fuzz_campaign(const FuzzCampaignOptions& options);

// The run of one input as the fuzz target sends it (the lines byte for byte
// through the port's host, or raw bytes from power-on), for the bound plus a
// second: what `avrbench fuzz --replay FILE` runs, with or without avr-gdb.
BoardRunOptions fuzz_replay_run(const FuzzCampaignOptions& options, const std::string& input);

}  // namespace avrbench
