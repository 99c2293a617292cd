// Golden comparison: an actual timeline against a golden one, channel by
// channel, each under the first rule whose pattern matches its name. The
// result names the first divergence (time, channel, expected vs actual, a few
// events of context) and has a per-channel summary.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trace/SignalChanges.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {

enum class RuleKind {
    Exact,     // every change at the same cycle with the same value (UART bytes, levels)
    Timing,    // same values in order; each change either within abs cycles of the golden one, or
               // the interval since the previous change within abs + rel x the golden interval
    Steps,     // same number of rising edges (never a lost or extra step); each within abs cycles
    StepRate,  // rising edges per window within rel x golden + 1
    PwmDuty,   // high-time fraction per window within `band` (absolute, 0..1)
    Band,      // real values: at every change of either, |actual - golden| <= band
    Ignore,
};

const char* to_string(RuleKind kind);

struct ChannelRule {
    std::string pattern = "*";  // glob on "scope.name": '*' any run, '?' one character
    RuleKind kind = RuleKind::Exact;
    double tolerance_cycles = 0;  // Timing, Steps
    double tolerance_rel = 0;     // Timing (fraction of the interval), StepRate (fraction of the rate)
    double window_s = 0.01;       // PwmDuty, StepRate
    double band = 0;              // PwmDuty (duty), Band (value units)
};

struct CompareOptions {
    std::vector<ChannelRule> rules;  // first match wins; none matching: Exact
    // Names that are one electrical wire (an MCU pin, the part pins on its
    // net, the net's and labels' names): a rule whose pattern matches any
    // of them applies to every one, so a tolerance belongs to the wire,
    // whatever name it is written with.
    std::vector<std::vector<std::string>> wires;
    std::size_t context_events = 3;
    // Ends of the two runs (for windowed rules); 0: the last event.
    Cycle golden_end_cycle = 0;
    Cycle actual_end_cycle = 0;
};

struct ChannelResult {
    std::string signal;
    RuleKind rule = RuleKind::Exact;
    bool passed = true;
    std::string verdict;  // "ok", "differs", "missing", "new" (not in the golden: not checked)
    std::string detail;   // one line
    std::size_t golden_changes = 0;
    std::size_t actual_changes = 0;
    bool diverges = false;
    Cycle divergence_cycle = 0;
    std::uint32_t clock_hz = 16000000;
    std::string expected;  // at the divergence
    std::string actual;
    std::vector<std::string> context;  // lines "golden | actual" around it
    double seconds() const { return static_cast<double>(divergence_cycle) / clock_hz; }
};

struct CompareResult {
    bool passed = true;
    std::vector<ChannelResult> channels;
    // The failing channel whose divergence comes first in time, or nullptr.
    const ChannelResult* first_divergence() const;
    // The human-readable diff: first divergence with context, then the table.
    std::string report() const;
};

CompareResult compare_timelines(const Timeline& golden, const Timeline& actual, const CompareOptions& options);
// The same on timelines held as their signals' changes (a streamed run, a golden read as changes).
CompareResult compare_changes(const TimelineChanges& golden, const TimelineChanges& actual, const CompareOptions& options);

bool glob_match(const std::string& pattern, const std::string& text);
// The rule `options` apply to `signal`: the first whose pattern matches it
// or another name of its wire (CompareOptions::wires); Exact when none does.
ChannelRule rule_for_signal(const std::string& signal, const CompareOptions& options);

}  // namespace avrbench
