// The firmware fuzz target's engine-independent part, shared by the libFuzzer
// front end (fuzz_firmware.cpp) and the AFL++ one (fuzz_firmware_afl.cpp).
//
// Configured by the environment (avrbench fuzz sets it):
//   AVRBENCH_FUZZ_BOARD  board file or standard board name
//   AVRBENCH_FUZZ_ELF    the firmware fuzzed: it runs on the MCU of the
//                        board's (first) serial port, whose edges are counted
//   AVRBENCH_FUZZ_FIRMWARE  the other MCUs' firmware on a multi-MCU board,
//                        "mcu=elf;mcu=elf" (as `run --firmware`); the board
//                        runs in its lockstep, coverage from the fuzzed MCU
//   AVRBENCH_FUZZ_FAMILY the host's firmware family (grbl, marlin, teacup,
//                        generic) when not the board's serial port's
//   AVRBENCH_FUZZ_BOUND  simulated seconds one input may take (default 3)
//   AVRBENCH_FUZZ_RAW    1: the input's bytes go to the serial port as they
//                        are, for binary protocols (seed 002's records): no
//                        host, so no banner to wait for (the firmware boots
//                        for AVRBENCH_FUZZ_BOOT seconds, default 0.2) and no
//                        hang oracle; the run ends the settle time after the
//                        last byte went in
//   AVRBENCH_FUZZ_HANG   1: a line still unanswered when the bound ends is a
//                        finding ("hang"), keep-alives or not (the
//                        serial port's line timeout is restarted by them)
//   AVRBENCH_FUZZ_STEADY AVR instructions after which an input that only
//                        repeats itself ends (default 100000; 0: never):
//                        the machine steps, no PC edge reached a new
//                        hit-count bucket, and no part could raise a finding
//                        going on at that pace until the bound (a carriage
//                        reaching an end of travel, a heater heating, a
//                        judged move under way: Part::may_find_more_at_pace)
//   AVRBENCH_FUZZ_SETTLE simulated seconds to keep running after the last
//                        answer, for what the lines set in motion (default 0.1:
//                        five RC-servo frames)
//   AVRBENCH_FUZZ_FORK   1: each input runs in a forked child of the booted
//                        process (the path before snapshots; also the one
//                        sanitizer builds take, whose malloc is not ours)
//
// When AVRBENCH_FUZZ_BOARD is not set, the same variables come from a file
// beside the executable, named after it with ".avrbench" added
// (`fuzz_firmware_x` reads `fuzz_firmware_x.avrbench`): NAME=VALUE lines,
// "$ORIGIN" in a value standing for the executable's directory. That is how
// a ClusterFuzzLite build (.clusterfuzzlite/build.sh) ships one fuzzer per
// firmware: a fuzzer there is only a binary, run without our environment.
//
// Once, at start-up, the firmware boots on the board until its host sees the
// family's banner (the board's serial port says which: grbl, marlin, teacup).
// The booted board is then snapshot (SnapshotHeap.hpp): per input,
// run_input_and_restore() sends the input's lines, runs the MCU, counts every
// program-counter edge (previous PC, PC) into the engine's map, so the search
// follows the firmware's branches, not the bench's, and puts the board back
// as it was booted, in this process. With AVRBENCH_FUZZ_FORK=1 the engine
// forks per input instead and the child calls run_input(). Either way an
// execution costs the input's own simulated time, not a boot.
//
// Oracles: every finding the MCU and board raise during the input (bad
// opcode, PC outside the program, stack into .bss, watchdog reset, bad
// interrupt, net faults, part limits); a line the firmware never answers
// within the serial port's line timeout (a hang); a fatal answer ("!!").
// "error" answers and restarts the firmware announces (grbl's ^X) are not
// findings.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace avrbench::fuzz {

struct TargetConfig {
    std::string board;
    std::string elf;
    std::map<std::string, std::string> other_firmware;  // MCU -> ELF, multi-MCU boards
    std::string family;    // empty: the board's
    double bound_s = 3.0;  // simulated time one input may take
    double settle_s = 0.1;
    bool raw = false;
    bool hang_at_bound = false;  // an unanswered line at the bound's end is a finding
    double boot_s = 0.2;   // raw mode: no banner, boot this long; generic family: at most this long
    // An input ends when the machine has only repeated itself for this many
    // AVR instructions (no new coverage feature while it steps, and no part
    // could find more at that pace before the bound); 0: run to the bound.
    std::uint64_t steady_instructions = 100000;
    bool fork = false;     // fork per input instead of restoring a snapshot
};

// From the AVRBENCH_FUZZ_* variables (or the file beside `executable`, see
// above); `who` names the program in the one-line error (exit 2) when one is
// missing.
TargetConfig config_from_environment(const char* who, const char* executable);

// Builds the board and boots the firmware to its ready state, then (unless
// it forks) takes the snapshot; on failure prints one line naming the cause
// and exits with 2.
void boot_target(const TargetConfig& config, const char* who);

// True when the inputs run in this process from the snapshot
// (run_input_and_restore), false when the engine must fork per input.
bool target_restores();

// What one input did (filled in the child, so engines put it in shared memory).
struct InputOutcome {
    std::uint64_t steps = 0;      // AVR instructions
    bool finding = false;
    bool ended_steady = false;    // ended repeating itself, before its bound
    char detail[512] = {};        // the first finding, one line
};

// Runs one input on the booted target, counting PC edges into
// edges[0..edge_mask]. Changes the target for good: call it in a forked child.
void run_input(const std::uint8_t* data, std::size_t size, std::uint8_t* edges, std::uint32_t edge_mask,
               InputOutcome& outcome);

// run_input() on the snapshot, then the board back as booted: the next input
// starts from exactly where this one did. Only when target_restores().
void run_input_and_restore(const std::uint8_t* data, std::size_t size, std::uint8_t* edges, std::uint32_t edge_mask,
                           InputOutcome& outcome);

// Everything of the booted board a run can observe, one "name value" line
// per item (MCU registers, RAM, flash, EEPROM, cycle, PC, every IRQ's
// value, pending interrupts and cycle timers; each net's level, each part's
// summary, the host's progress, the findings): the snapshot test compares
// the board after a restore with the board as booted.
std::string observable_state();

bool target_is_raw();

}  // namespace avrbench::fuzz
