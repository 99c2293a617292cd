// Scenario files: a board, its firmware, stimulus steps, expectations, and a
// golden timeline with tolerances, as a person would describe a bench test.
//
//   name: stepdir_x_move
//   board: ../../bench/boards/arduino-uno-cnc-shield-v3.yaml  # relative to this file
//   firmware: {uno: stepdir_test}       # a name: <build>/firmware/<name>.elf; or a path
//   time_limit: 2s                      # for the whole scenario (simulated)
//   steps:
//     - wait_for_text: ready            # a line from the firmware containing it
//     - send: X1600                     # one line through the serial host
//     - send_file: jobs/square.gcode    # a job, streamed with the port's flow control
//     - wait_idle: 50ms                 # hosts finished, no STEP edge for 50 ms
//     - wait_pin: {pin: uno.PB0, level: 0}
//     - delay: 10ms
//     - set_input: {pin: uno.PC5, level: 0}   # drive an MCU pin (a label works too)
//     - release_input: uno.PC5
//   expect:
//     - steps: {axis: x, count: 1600}
//     - position: {axis: x, mm: 106.4, within: 0.001}
//     - pin: {pin: uno.PB0, level: 0}
//     - text: "X:1600"                  # somewhere in what the firmware sent
//     - findings: 0                     # or a list of kinds: [step-high-too-short]
//   golden: ../../golden/stepdir_x_move.timeline
//   golden_signals: ["uno.*", "hotend.temperature_degC"]  # default: every wire and bus
//   tolerances:                         # first match wins; unmatched signals are exact
//     - {signals: "uno.PD*", rule: steps, cycles: 4}
//     - {signals: "*.position_mm", rule: band, band: 0.001}
//
// Errors in the file are BadInput "file:line: ...".
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "verify/TimelineCompare.hpp"

namespace avrbench {

struct ScenarioStep {
    std::string kind;  // wait_for_text, send, send_file, wait_idle, wait_pin, delay, set_input, release_input, inject_fault
    std::map<std::string, std::string> args;  // "value" for the scalar form
    std::string location;
};

struct ScenarioExpectation {
    std::string kind;  // steps, position, pin, text, findings
    std::map<std::string, std::string> args;
    std::vector<std::string> list;  // findings: [kinds]
    std::string location;
};

struct ScenarioSpec {
    std::string path;
    std::string name;
    std::string description;
    std::string board_path;                      // resolved
    std::map<std::string, std::string> firmware;  // MCU -> resolved ELF path
    double time_limit_s = 10.0;
    std::vector<ScenarioStep> steps;
    std::vector<ScenarioExpectation> expectations;
    std::string golden_path;  // resolved; empty: no golden comparison
    // Globs of the signals the golden holds. Empty: every wire and bus (real
    // signals such as positions follow from the step edges and would only
    // make the file long; list them to pin them, e.g. temperatures).
    std::vector<std::string> golden_signals;
    std::vector<ChannelRule> tolerances;
};

// `firmware_dir` resolves bare firmware names (e.g. build/firmware).
ScenarioSpec load_scenario(const std::string& path, const std::string& firmware_dir);

struct ScenarioResult {
    std::string name;
    bool passed = false;
    std::vector<std::string> failures;  // one line each: steps, expectations, golden
    std::optional<CompareResult> comparison;
    double simulated_s = 0;
    double wall_s = 0;
    std::string report_path;  // HTML report, if written
    std::string text() const;  // the human-readable outcome (failures, then the diff report)
};

struct ScenarioRunOptions {
    std::string report_dir;      // write <report_dir>/<name>.html (and .vcd) when set
    bool update_golden = false;  // write the golden timeline instead of comparing
};

ScenarioResult run_scenario(const ScenarioSpec& spec, const ScenarioRunOptions& options);

// JUnit XML for CI systems: one <testsuite> with one <testcase> per result.
std::string junit_xml(const std::vector<ScenarioResult>& results, const std::string& suite_name);

}  // namespace avrbench
