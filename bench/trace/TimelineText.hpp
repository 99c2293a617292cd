// The golden-timeline file format: text, line-oriented, stable ordering,
// compact, readable as a git diff. Exact: cycles and values as recorded;
// tolerances live in the comparison, never in the file.
//
//   avrbench-timeline 1
//   bench 0.1.0
//   input firmware.uno 3f2a...  build/firmware/stepdir_test.elf
//   input board 91bc...  bench/boards/arduino-uno-cnc-shield-v3.yaml
//   input stimulus 07d1...  tests/scenarios/x_move.yaml
//   end 1600012 16000000
//   signal uno.PD2 wire 1 16000000
//   signal uno.uart0_tx bus 8 16000000
//   signal x.position_mm real 64 16000000
//
//   @uno.PD2
//   0 0
//   +1696 1
//   +32 0
//   *99 +320 1 +32 0
//
// After "@<signal>", the first line is "<cycle> <value>", each next one
// "+<cycles since the previous change> <value>", and "*<n> <block>" repeats a
// block of one or two such pairs n times (run-length encoding of periodic
// signals: a 1600-step move is a few lines, and a shifted step shows up as a
// one-line change in a diff). Values: 0/1 for wires, decimal for buses, the
// shortest exact decimal for reals. Only changes are stored: an event that
// repeats the previous value is dropped. Signals appear in the order they were
// declared in the timeline; cycles are in the signal's own clock.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "trace/SignalChanges.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {

struct TimelineInput {
    std::string role;  // "firmware.uno", "board", "stimulus"
    std::string sha256;
    std::string path;
};

struct TimelineHeader {
    std::string bench_version;
    std::vector<TimelineInput> inputs;
    Cycle end_cycle = 0;
    std::uint32_t end_clock_hz = 0;
};

// `jitter_cycles`: per signal ("scope.name") how far an edge may sit from its
// nominal place. A constant-rate train whose edges all lie within that of a
// fixed period is written as one `*n` block of nominal deltas (the intent)
// instead of its jitter: the golden's edges are then the nominal ones, each
// within the bound of what was recorded, and the rule that gave the bound
// (a `steps` tolerance) accepts them. Signals not named are written exactly.
std::string format_timeline_text(const Timeline& timeline, const TimelineHeader& header,
                                 const std::map<std::string, Cycle>& jitter_cycles = {});
void write_timeline_text(const Timeline& timeline, const TimelineHeader& header, const std::string& path,
                         const std::map<std::string, Cycle>& jitter_cycles = {});
// The same from a timeline held as its signals' changes (a streamed run).
std::string format_timeline_text(const TimelineChanges& timeline, const TimelineHeader& header,
                                 const std::map<std::string, Cycle>& jitter_cycles = {});
void write_timeline_text(const TimelineChanges& timeline, const TimelineHeader& header, const std::string& path,
                         const std::map<std::string, Cycle>& jitter_cycles = {});

struct ParsedTimeline {
    TimelineHeader header;
    Timeline timeline;
};
// Throws BadInput "<source>:<line>: ..." on anything it does not understand:
// every word of every line is read, or the line is refused. An event after
// the timeline's own `end` is malformed. With stop_after_s > 0 (the end of
// the run it will be compared with), each signal keeps its first event after
// that time and no later one - not even expanded - so a golden that claims
// more than the run could show costs no more than the run.
ParsedTimeline parse_timeline_text(const std::string& text, const std::string& source, double stop_after_s = 0);
ParsedTimeline read_timeline_text(const std::string& path, double stop_after_s = 0);

// The same, the events held as each signal's changes (SignalChanges: 8 bytes
// a wire change), for comparing a long run without a Timeline of each side.
struct ParsedChanges {
    TimelineHeader header;
    TimelineChanges changes;
};
ParsedChanges read_timeline_changes(const std::string& path, double stop_after_s = 0);

// Events of one signal with unchanged values removed, in time order.
std::vector<TimelineEvent> changes_of(const Timeline& timeline, SignalId id);

}  // namespace avrbench
