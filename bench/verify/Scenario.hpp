// Scenario files: a board, its firmware, stimulus steps, expectations, and a
// golden timeline with tolerances, as a person would describe a bench test.
// Every key is listed with an example in docs/SCENARIOS.md.
//
//   name: stepdir_x_move
//   board: ../../bench/boards/arduino-uno-cnc-shield-v3.yaml  # relative to this file
//   firmware: {uno: stepdir_test}       # a name: <firmware dir>/<name>.elf; or a path
//   time_limit: 2s                      # for the whole scenario (simulated)
//   steps:
//     - wait_for_text: ready
//     - send: X1600
//     - wait_idle: 50ms
//   expect:
//     - steps: {axis: x, count: 1600}
//   golden: ../../golden/stepdir_x_move.timeline
//
// load_scenario() checks the whole file before anything runs: YAML types,
// units, files, and every axis, part, pin, label and serial port it names
// against the board file. Errors are BadInput "file:line: ...".
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/Time.hpp"
#include "stimulus/BenchSteps.hpp"
#include "verify/TimelineCompare.hpp"

namespace avrbench {
class Bench;
}

namespace avrbench {

struct ScenarioStep {
    StepAction action;
    std::string kind;      // as written: "send", "wait_idle", ...
    std::string location;  // file:line
};

// --- expectations: checked once the steps are done ---------------------------
struct ExpectSteps { std::string axis; std::uint64_t count = 0; };
struct ExpectPosition { std::string axis; double value = 0; double within = 1e-6; };  // mm, or deg on a rotary axis
struct ExpectPin { std::string pin; bool level = false; };
struct ExpectText { std::string text; };
// A display part's text (an hd44780's lines) matches `pattern` (RE2): on line
// `line` (1-based), or anywhere in the lines joined with newlines (line 0).
struct ExpectLcdShows { std::string part; int line = 0; std::string pattern; };
// A part's signal (PART.SIGNAL, as the VCD names it: hotend.block_degC)
// stayed within [min, max] from `from_ps` to the end of the run: the value in
// force at `from_ps` and every change after it.
struct ExpectSignal {
    std::string part, signal;
    std::optional<double> min, max;
    Picoseconds from_ps = 0;
};
struct ExpectFindingCount { std::uint64_t count = 0; };
struct ExpectFindingKinds { std::vector<std::string> kinds; };  // as a multiset

// Timing profile bounds (mcu/TimingProfile.hpp); `mcu` "" = the board's first.
// A scenario with any of them profiles that MCU.
struct ExpectIsr {
    std::string mcu;
    int vector = 0;
    std::optional<std::uint64_t> max_cycles, max_latency_cycles, min_runs;  // inclusive execution time
};
struct ExpectStack { std::string mcu; std::int64_t min_headroom_bytes = 0; };
struct ExpectInterruptsOff { std::string mcu; std::uint64_t max_cycles = 0; };
struct ExpectCpu { std::string mcu; double max_busy_percent = 100; };  // executing / (executing + asleep + idle loop)
using ExpectAction = std::variant<ExpectSteps, ExpectPosition, ExpectPin, ExpectText, ExpectLcdShows, ExpectSignal,
                                  ExpectFindingCount, ExpectFindingKinds, ExpectIsr, ExpectStack, ExpectInterruptsOff, ExpectCpu>;

struct ScenarioExpectation {
    ExpectAction action;
    std::string kind;
    std::string location;
};

struct ScenarioSpec {
    std::string path;
    std::string name;
    std::string description;
    std::string board_path;                       // resolved
    std::map<std::string, std::string> firmware;  // MCU -> resolved ELF path
    Picoseconds time_limit_ps = 10 * kPsPerSecond;
    std::vector<ScenarioStep> steps;
    std::vector<ScenarioExpectation> expectations;
    std::string golden_path;  // resolved; empty: no golden comparison
    // Globs of the signals the golden holds. Empty: every wire and bus.
    std::vector<std::string> golden_signals;
    std::vector<ChannelRule> tolerances;
    // `host: {family, line_timeout}`: the first serial port's host, instead of
    // what the board file declares (e.g. our own firmware on a grbl board).
    std::optional<std::string> host_family;
    std::optional<std::string> host_error_pattern;  // besides the family's error lines
    std::optional<Picoseconds> host_line_timeout_ps;
    // Paths of send_file steps, resolved.
    std::vector<std::string> stimulus_files() const;
};

// `firmware_dir` resolves bare firmware names (e.g. build/firmware).
ScenarioSpec load_scenario(const std::string& path, const std::string& firmware_dir);

// A scenario name as it may appear in a file name, a JUnit attribute or an
// HTML title: printable, no path separators, at most kMaxScenarioNameBytes.
constexpr std::size_t kMaxScenarioNameBytes = 120;

struct ScenarioResult {
    std::string name;
    std::string path;                   // the scenario file
    bool passed = false;
    bool error = false;                 // could not load or run: bad input, not a failed check
    std::vector<std::string> failures;  // one line each: steps, expectations, golden; or the error
    std::vector<std::string> expectation_failures;  // the subset of failures from steps and expectations
    std::optional<CompareResult> comparison;
    double simulated_s = 0;
    double wall_s = 0;
    std::string report_path;   // HTML report, if written
    std::string vcd_path;      // VCD (with a .gtkw beside it), if written
    // The comparison (or golden update) took the run's changes as they were recorded, the
    // timeline holding none (no report, VCD or debugger needed it whole).
    bool streamed = false;
    std::string text() const;  // the human-readable outcome (failures, then the diff report)
};

// The result of a scenario that could not be loaded or run: `message` is the
// BadInput line (file:line: ...).
ScenarioResult error_result(const std::string& path, const std::string& message);

struct ScenarioRunOptions {
    std::string report_dir;      // write <report_dir>/<name>.html when set
    std::string vcd_dir;         // write <vcd_dir>/<name>.vcd and .gtkw when set
    bool update_golden = false;  // write the golden timeline instead of comparing
    bool force = false;          // update_golden: also when steps or expectations failed
    // Called once the board is built and traced, before the first step (a
    // debugger attaches to its MCUs here; `avrbench check --gdb`).
    std::function<void(Bench&)> prepared;
};

// Runs the scenario. Throws BadInput only for problems that show when the
// board is built (e.g. an ELF built for another MCU, an unknown fault name).
ScenarioResult run_scenario(const ScenarioSpec& spec, const ScenarioRunOptions& options);

}  // namespace avrbench
