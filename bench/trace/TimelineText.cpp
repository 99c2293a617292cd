#include "trace/TimelineText.hpp"

#include "core/OutputFile.hpp"

#include <algorithm>
#include <charconv>
#include <limits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <fstream>
#include <sstream>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {
namespace {

const char* kind_name(SignalKind k) {
    switch (k) {
        case SignalKind::Wire: return "wire";
        case SignalKind::Bus: return "bus";
        case SignalKind::Real: return "real";
    }
    return "wire";
}

std::string format_value(const SignalInfo& info, const TimelineEvent& e) {
    if (info.kind == SignalKind::Real) {
        char buf[64];
        auto [end, ec] = std::to_chars(buf, buf + sizeof buf, e.value.real);
        (void)ec;
        return std::string(buf, end);
    }
    return std::to_string(e.value.bits);
}

bool same_value(const SignalInfo& info, const TimelineEvent& a, const TimelineEvent& b) {
    return info.kind == SignalKind::Real ? a.value.real == b.value.real : a.value.bits == b.value.bits;
}

// A change after the first: cycles since the previous one, and its value
// (a real's as its bits: equal bits, equal shortest decimal).
struct Pair {
    Cycle delta;
    std::uint64_t value;
    bool operator==(const Pair& o) const { return delta == o.delta && value == o.value; }
};

std::string format_bits(const SignalInfo& info, std::uint64_t bits) {
    TimelineEvent e{0, 0, {}};
    e.value.bits = bits;
    return format_value(info, e);
}

std::string full_name(const SignalInfo& s) { return s.scope + "." + s.name; }

}  // namespace

namespace {

// Sorted by cycle (stable: at one cycle the last recorded value wins, as in
// the VCD writer), repeats of the previous value dropped.
std::vector<TimelineEvent> dedupe(std::vector<TimelineEvent> events, const SignalInfo& info) {
    if (!std::is_sorted(events.begin(), events.end(),
                        [](const TimelineEvent& a, const TimelineEvent& b) { return a.cycle < b.cycle; })) {
        std::stable_sort(events.begin(), events.end(),
                         [](const TimelineEvent& a, const TimelineEvent& b) { return a.cycle < b.cycle; });
    }
    // In place: `kept` events are the result so far.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const TimelineEvent e = events[i];
        if (kept > 0 && events[kept - 1].cycle == e.cycle) {
            events[kept - 1] = e;
            if (kept >= 2 && same_value(info, events[kept - 2], events[kept - 1])) --kept;
            continue;
        }
        if (kept > 0 && same_value(info, events[kept - 1], e)) continue;
        events[kept++] = e;
    }
    events.resize(kept);
    return events;
}

}  // namespace

std::vector<TimelineEvent> changes_of(const Timeline& timeline, SignalId id) {
    std::vector<TimelineEvent> events;
    for (const auto& e : timeline.events()) {
        if (e.signal == id) events.push_back(e);
    }
    return dedupe(std::move(events), timeline.signals()[id]);
}

namespace {

// The exact form: a block of 1 or 2 pairs repeated 3 or more times becomes
// one line. `pair(i)` gives the i-th of `count` pairs.
template <class PairAt>
void append_exact(std::string& out, const SignalInfo& info, std::size_t count, PairAt pair) {
    std::size_t i = 0;
    while (i < count) {
        bool emitted = false;
        for (std::size_t block = 1; block <= 2 && !emitted; ++block) {
            std::size_t repeats = 1;
            while (i + (repeats + 1) * block <= count) {
                bool same = true;
                for (std::size_t k = 0; k < block; ++k) same = same && pair(i + repeats * block + k) == pair(i + k);
                if (!same) break;
                ++repeats;
            }
            if (repeats >= 3) {
                out += "*" + std::to_string(repeats);
                for (std::size_t k = 0; k < block; ++k) {
                    out += " +" + std::to_string(pair(i + k).delta) + " " + format_bits(info, pair(i + k).value);
                }
                out += "\n";
                i += repeats * block;
                emitted = true;
            }
        }
        if (!emitted) {
            out += "+" + std::to_string(pair(i).delta) + " " + format_bits(info, pair(i).value) + "\n";
            ++i;
        }
    }
}

void append_exact(std::string& out, const SignalInfo& info, const std::vector<Pair>& pairs) {
    append_exact(out, info, pairs.size(), [&pairs](std::size_t i) { return pairs[i]; });
}

// A run of `repeats` blocks of `block` events from changes[i] on, each event
// within `jitter` of prev + k * period + offset[j]: its nominal form, or
// nothing when no such run of 3 or more blocks starts there.
struct NominalBlock {
    std::size_t repeats = 0;
    Cycle period = 0;
    std::vector<Cycle> offsets;  // of each event in the block from the block's start, the last = period
};

NominalBlock fit_block(const SignalChanges& changes, std::size_t i, std::size_t block, Cycle prev, Cycle jitter) {
    const std::size_t n = changes.size();
    const auto cycles = [&changes](std::size_t k) { return changes.cycle(k); };
    std::size_t repeats = 0;
    while (i + (repeats + 1) * block <= n) {
        bool same = true;
        for (std::size_t j = 0; j < block; ++j) same = same && changes.bits(i + repeats * block + j) == changes.bits(i + j);
        if (!same) break;
        ++repeats;
    }
    // Fit, check, shrink to the first block that does not fit, a bounded number of times.
    for (int attempt = 0; attempt < 24 && repeats >= 3; ++attempt) {
        NominalBlock fit;
        fit.repeats = repeats;
        const Cycle last = cycles(i + repeats * block - 1);
        if (last <= prev) return {};
        fit.period = (last - prev + repeats / 2) / repeats;
        if (fit.period == 0) return {};
        for (std::size_t j = 0; j < block; ++j) {
            if (j + 1 == block) {
                fit.offsets.push_back(fit.period);
                break;
            }
            // The mean offset of event j from its block's nominal start.
            long double sum = 0;
            for (std::size_t k = 0; k < repeats; ++k) {
                sum += static_cast<long double>(cycles(i + k * block + j)) - static_cast<long double>(prev + k * fit.period);
            }
            const long double mean = sum / static_cast<long double>(repeats);
            if (mean < 1) return {};
            fit.offsets.push_back(static_cast<Cycle>(mean + 0.5L));
        }
        bool increasing = true;
        for (std::size_t j = 1; j < fit.offsets.size(); ++j) increasing = increasing && fit.offsets[j] > fit.offsets[j - 1];
        if (!increasing) return {};
        std::size_t fits = repeats;
        for (std::size_t k = 0; k < repeats && fits == repeats; ++k) {
            for (std::size_t j = 0; j < block; ++j) {
                const Cycle nominal = prev + k * fit.period + fit.offsets[j];
                const Cycle actual = cycles(i + k * block + j);
                if ((actual > nominal ? actual - nominal : nominal - actual) > jitter) {
                    fits = k;
                    break;
                }
            }
        }
        // The next event must come after the block's nominal end (deltas are never negative).
        const std::size_t after = i + repeats * block;
        if (fits == repeats && after < n && cycles(after) < prev + repeats * fit.period) fits = repeats - 1;
        if (fits == repeats) return fit;
        repeats = fits;
    }
    return {};
}

void append_nominal(std::string& out, const SignalChanges& changes, const SignalInfo& info, Cycle jitter) {
    Cycle prev = changes.cycle(0);
    std::size_t i = 1;
    std::vector<Pair> pending;  // exact pairs between blocks
    while (i < changes.size()) {
        NominalBlock best;
        std::size_t best_block = 0;
        for (std::size_t block = 1; block <= 2; ++block) {
            NominalBlock fit = fit_block(changes, i, block, prev, jitter);
            if (fit.repeats * block > best.repeats * best_block) {
                best = std::move(fit);
                best_block = block;
            }
        }
        if (best.repeats < 3) {
            pending.push_back({changes.cycle(i) - prev, changes.bits(i)});
            prev = changes.cycle(i);
            ++i;
            continue;
        }
        append_exact(out, info, pending);
        pending.clear();
        out += "*" + std::to_string(best.repeats);
        Cycle at = 0;
        for (std::size_t j = 0; j < best_block; ++j) {
            out += " +" + std::to_string(best.offsets[j] - at) + " " + format_bits(info, changes.bits(i + j));
            at = best.offsets[j];
        }
        out += "\n";
        prev += best.repeats * best.period;
        i += best.repeats * best_block;
    }
    append_exact(out, info, pending);
}

}  // namespace

std::string format_timeline_text(const TimelineChanges& timeline, const TimelineHeader& header,
                                 const std::map<std::string, Cycle>& jitter_cycles) {
    std::string out = "avrbench-timeline 1\n";
    out += "bench " + header.bench_version + "\n";
    for (const auto& in : header.inputs) out += "input " + in.role + " " + in.sha256 + " " + in.path + "\n";
    out += "end " + std::to_string(header.end_cycle) + " " + std::to_string(header.end_clock_hz) + "\n";
    const auto& signals = timeline.signals;
    for (const auto& s : signals) {
        out += "signal " + full_name(s) + " " + kind_name(s.kind) + " " +
               std::to_string(s.kind == SignalKind::Real ? 64u : s.width) + " " + std::to_string(s.clock_hz) + "\n";
    }
    for (SignalId id = 0; id < signals.size(); ++id) {
        const SignalInfo& info = signals[id];
        out += "\n@" + full_name(info) + "\n";
        const SignalChanges& changes = timeline.changes[id];
        if (changes.empty()) continue;
        out += std::to_string(changes.cycle(0)) + " " + format_bits(info, changes.bits(0)) + "\n";
        const auto jitter = jitter_cycles.find(full_name(info));
        if (jitter != jitter_cycles.end() && jitter->second > 0) {
            append_nominal(out, changes, info, jitter->second);
            continue;
        }
        append_exact(out, info, changes.size() - 1, [&changes](std::size_t i) {
            return Pair{changes.cycle(i + 1) - changes.cycle(i), changes.bits(i + 1)};
        });
    }
    return out;
}

std::string format_timeline_text(const Timeline& timeline, const TimelineHeader& header,
                                 const std::map<std::string, Cycle>& jitter_cycles) {
    return format_timeline_text(timeline_changes(timeline), header, jitter_cycles);
}

void write_timeline_text(const Timeline& timeline, const TimelineHeader& header, const std::string& path,
                         const std::map<std::string, Cycle>& jitter_cycles) {
    write_output_file(path, format_timeline_text(timeline, header, jitter_cycles), "golden timeline");
}

void write_timeline_text(const TimelineChanges& timeline, const TimelineHeader& header, const std::string& path,
                         const std::map<std::string, Cycle>& jitter_cycles) {
    write_output_file(path, format_timeline_text(timeline, header, jitter_cycles), "golden timeline");
}

// A bound on what one golden file may expand to (events after run-length
// decoding): 50 million events are about 1.2 GB in memory. A longer run
// belongs in a golden of selected signals (golden_signals) or a window rule.
constexpr std::uint64_t kMaxGoldenEvents = 50'000'000;

namespace {

// The golden-timeline text parser: one method per kind of line. Every word
// of a line is read or the line is refused; errors name source:line.
class TimelineTextParser {
public:
    // With `into`, events go there (each signal's changes) instead of the
    // parsed timeline, which then holds only the signals.
    TimelineTextParser(std::string_view text, const std::string& source, double stop_after_s, TimelineChanges* into = nullptr)
        : text_(text), source_(source), stop_after_s_(stop_after_s), into_(into) {}

    ParsedTimeline parse() {
        if (!next_line() || line_ != "avrbench-timeline 1") fail("not an avrbench timeline (expected 'avrbench-timeline 1')");
        while (next_line()) {
            if (line_.empty()) continue;
            std::istringstream ls(line_);
            std::string word;
            ls >> word;
            if (word == "bench") {
                if (!(ls >> parsed_.header.bench_version)) fail("'bench' needs the version that wrote the file");
                no_more(ls, "the bench version");
            } else if (word == "input") {
                TimelineInput input;
                if (!(ls >> input.role >> input.sha256)) fail("'input' needs a role, a SHA-256 and a path");
                std::getline(ls >> std::ws, input.path);
                parsed_.header.inputs.push_back(input);
            } else if (word == "end") {
                parse_end(ls);
            } else if (word == "signal") {
                parse_signal(ls);
            } else if (word[0] == '@') {
                begin_events(word.substr(1), ls);
            } else if (current_ < 0) {
                fail("unexpected '" + line_ + "'");
            } else if (word[0] == '*') {
                parse_repeat(word, ls);
            } else {
                std::string value;
                if (!(ls >> value)) fail("'" + word + "' has no value");
                no_more(ls, "a change");
                record(word[0] == '+' ? last_cycle_ + parse_cycles(word.substr(1)) : parse_cycles(word), value);
            }
        }
        // A golden that records nothing passes every run: no check at all.
        if (parsed_.timeline.signals().empty()) {
            fail("holds no signal; a golden records the signals a run is checked on (avrbench golden update writes one)");
        }
        if (into_ != nullptr) {
            for (auto& c : into_->changes) c.finish();
        }
        return std::move(parsed_);
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw BadInput(escaped(source_) + ":" + std::to_string(line_no_) + ": " + escaped(what));
    }
    void no_more(std::istringstream& words, const char* what) const {
        std::string extra;
        if (words >> extra) fail("'" + extra + "' after " + what + " (one item per line)");
    }
    bool next_line() {
        if (pos_ >= text_.size()) return false;
        const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
        line_.assign(text_.substr(pos_, end - pos_));
        pos_ = end + 1;
        ++line_no_;
        if (!line_.empty() && line_.back() == '\r') line_.pop_back();
        return true;
    }
    std::uint64_t parse_u64(const std::string& s) const {
        std::uint64_t v = 0;
        auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc() || end != s.data() + s.size()) fail("'" + s + "' is not a whole number");
        return v;
    }
    // A cycle count or a cycle delta: bounded so that sums never wrap.
    Cycle parse_cycles(const std::string& s) const {
        const std::uint64_t v = parse_u64(s);
        if (v > (std::uint64_t{1} << 53)) fail("cycle count " + s + " is past any run's end");
        return v;
    }

    void parse_end(std::istringstream& ls) {
        std::string c, f;
        if (!(ls >> c >> f)) fail("'end' needs a cycle and a clock in Hz");
        no_more(ls, "the end cycle and clock");
        parsed_.header.end_cycle = parse_cycles(c);
        const std::uint64_t hz = parse_u64(f);
        if (hz == 0 || hz > 64'000'000) fail("end clock " + f + " Hz is not 1 Hz .. 64 MHz");
        if (parsed_.header.end_cycle > hz * 1'000'000ULL) fail("end " + c + " is past 10^6 s at " + f + " Hz");
        parsed_.header.end_clock_hz = static_cast<std::uint32_t>(hz);
    }

    void parse_signal(std::istringstream& ls) {
        std::string name, kind, width, clock;
        if (!(ls >> name >> kind >> width >> clock)) fail("'signal' needs scope.name, kind, width and clock");
        no_more(ls, "the signal's clock");
        const auto dot = name.find('.');
        if (dot == std::string::npos) fail("signal '" + name + "' has no scope");
        SignalInfo info;
        info.scope = name.substr(0, dot);
        info.name = name.substr(dot + 1);
        if (kind == "wire") info.kind = SignalKind::Wire;
        else if (kind == "bus") info.kind = SignalKind::Bus;
        else if (kind == "real") info.kind = SignalKind::Real;
        else fail("unknown signal kind '" + kind + "'");
        const std::uint64_t bits = info.kind == SignalKind::Real ? 1 : parse_u64(width);
        if (info.kind == SignalKind::Wire && bits != 1) fail("a wire is 1 bit wide, not " + width);
        if (bits < 1 || bits > 64) fail("bus width " + width + " is not 1..64");
        info.width = static_cast<unsigned>(bits);
        const std::uint64_t hz = parse_u64(clock);
        if (hz == 0 || hz > 64'000'000) fail("clock " + clock + " Hz is not 1 Hz .. 64 MHz");
        info.clock_hz = static_cast<std::uint32_t>(hz);
        if (info.scope.empty() || info.name.empty()) fail("signal '" + name + "' has an empty scope or name");
        if (parsed_.timeline.find(info.scope, info.name) >= 0) fail("signal '" + name + "' is declared twice");
        try {
            parsed_.timeline.add_signal(info);
        } catch (const std::invalid_argument& e) {
            fail(e.what());
        }
        if (into_ != nullptr) {
            into_->signals.push_back(info);
            into_->changes.emplace_back(info.kind);
        }
    }

    // "@scope.name": the events that follow are this signal's.
    void begin_events(const std::string& name, std::istringstream& ls) {
        const auto dot = name.find('.');
        current_ = dot == std::string::npos ? -1 : parsed_.timeline.find(name.substr(0, dot), name.substr(dot + 1));
        if (current_ < 0) fail("events for undeclared signal '" + name + "'");
        no_more(ls, "the signal's name");
        last_cycle_ = 0;
        stopped_ = false;
        // The bounds in this signal's clock (end cycle x clock / end clock, exact enough: whole cycles).
        const double hz = parsed_.timeline.signals()[static_cast<std::size_t>(current_)].clock_hz;
        end_bound_ = parsed_.header.end_clock_hz == 0
                         ? std::numeric_limits<Cycle>::max()
                         : static_cast<Cycle>(std::ceil(static_cast<double>(parsed_.header.end_cycle) * hz / parsed_.header.end_clock_hz));
        stop_bound_ = stop_after_s_ > 0 ? static_cast<Cycle>(std::ceil(stop_after_s_ * hz)) : std::numeric_limits<Cycle>::max();
    }

    // "*n +d v +d v ...": the block of deltas and values n times.
    void parse_repeat(const std::string& word, std::istringstream& ls) {
        const std::uint64_t repeats = parse_u64(word.substr(1));
        if (repeats > kMaxGoldenEvents) fail("repeat count " + word.substr(1) + " is more than the events a golden may hold");
        std::vector<std::pair<Cycle, std::string>> block;
        std::string delta, value;
        while (ls >> delta) {
            if (delta.empty() || delta[0] != '+') fail("repeat block needs +delta value pairs, not '" + delta + "'");
            if (!(ls >> value)) fail("repeat block: '" + delta + "' has no value");
            block.emplace_back(parse_cycles(delta.substr(1)), value);
        }
        if (block.empty()) fail("empty repeat block");
        // Checked before expanding, so an oversized block allocates nothing.
        if (repeats > (kMaxGoldenEvents - events_) / block.size()) {
            fail("more than " + std::to_string(kMaxGoldenEvents) + " events (the most a golden timeline may hold)");
        }
        Cycle block_cycles = 0;
        for (const auto& [d, v] : block) block_cycles += d;
        for (std::uint64_t r = 0; r < repeats; ++r) {
            for (const auto& [d, v] : block) record(last_cycle_ + d, v);
            if (stopped_) {
                // Past the compared run's end: what is left only moves the
                // clock on (and is checked against the timeline's end).
                const std::uint64_t left = repeats - r - 1;
                if (block_cycles != 0 && left > ((std::uint64_t{1} << 53) - last_cycle_) / block_cycles) {
                    fail("the repeat runs past any run's end");
                }
                last_cycle_ += left * block_cycles;
                if (last_cycle_ > end_bound_) fail("cycle " + std::to_string(last_cycle_) + " is after the timeline's end");
                break;
            }
        }
    }

    void record(Cycle cycle, const std::string& value) {
        // 10^6 s at 64 MHz is 6.4e13 cycles; 2^53 bounds the sums below too.
        if (cycle > (std::uint64_t{1} << 53)) fail("cycle " + std::to_string(cycle) + " is past any run's end");
        if (cycle > end_bound_) fail("cycle " + std::to_string(cycle) + " is after the timeline's end");
        if (stopped_) {
            last_cycle_ = cycle;
            return;
        }
        stopped_ = cycle > stop_bound_;
        if (++events_ > kMaxGoldenEvents) {
            fail("more than " + std::to_string(kMaxGoldenEvents) + " events (the most a golden timeline may hold)");
        }
        const SignalInfo& info = parsed_.timeline.signals()[static_cast<std::size_t>(current_)];
        if (info.kind == SignalKind::Real) {
            double v = 0;
            auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
            if (ec != std::errc() || end != value.data() + value.size()) fail("'" + value + "' is not a number");
            if (into_ != nullptr) {
                std::uint64_t bits = 0;
                std::memcpy(&bits, &v, sizeof bits);
                into_->changes[static_cast<std::size_t>(current_)].add(cycle, bits);
            } else {
                parsed_.timeline.record_real(static_cast<SignalId>(current_), cycle, v);
            }
        } else if (into_ != nullptr) {
            into_->changes[static_cast<std::size_t>(current_)].add(cycle, parse_u64(value));
        } else {
            parsed_.timeline.record(static_cast<SignalId>(current_), cycle, parse_u64(value));
        }
        last_cycle_ = cycle;
    }

    std::string_view text_;
    std::size_t pos_ = 0;  // where the next line starts
    const std::string& source_;
    const double stop_after_s_;
    TimelineChanges* into_;
    ParsedTimeline parsed_;
    std::string line_;
    int line_no_ = 0;
    long current_ = -1;  // the signal whose events these are
    Cycle last_cycle_ = 0;
    std::uint64_t events_ = 0;
    // Where this signal's events stop being kept: its clock's cycle at the
    // golden's own end (an event after it is malformed) and at stop_after_s
    // (the run compared with it ended there: a later event is kept once, to
    // show the difference, and the rest not even expanded).
    Cycle end_bound_ = std::numeric_limits<Cycle>::max(), stop_bound_ = std::numeric_limits<Cycle>::max();
    bool stopped_ = false;  // this signal passed stop_bound
};

}  // namespace

ParsedTimeline parse_timeline_text(const std::string& text, const std::string& source, double stop_after_s) {
    return TimelineTextParser(text, source, stop_after_s).parse();
}

ParsedTimeline read_timeline_text(const std::string& path, double stop_after_s) {
    return parse_timeline_text(read_input_file(path, "golden timeline", kMaxGoldenFileBytes), path, stop_after_s);
}

ParsedChanges read_timeline_changes(const std::string& path, double stop_after_s) {
    ParsedChanges out;
    const std::string text = read_input_file(path, "golden timeline", kMaxGoldenFileBytes);
    out.header = TimelineTextParser(text, path, stop_after_s, &out.changes).parse().header;
    return out;
}

}  // namespace avrbench
