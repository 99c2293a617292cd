// The timeline recorder: every traced signal change with the cycle it happened on.
//
// Recording is on the simulation's hot path (a pin IRQ fires for every PORT write),
// so record() is an inline append to one flat vector; everything else (sorting
// across clock domains, formatting) happens when a writer reads the timeline.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/Time.hpp"

namespace avrbench {

enum class SignalKind : std::uint8_t {
    Wire,  // 1-bit digital signal
    Bus,   // `width` bits, e.g. a UART byte or an 8-bit port
    Real,  // analog value (volts, degC, ...) stored as double
};

struct SignalInfo {
    std::string scope;  // one scope per MCU and per part, e.g. "mcu" or "x_driver"
    std::string name;   // e.g. "PB5", "uart0_tx"
    SignalKind kind = SignalKind::Wire;
    unsigned width = 1;                 // bits; 1 for Wire, ignored for Real
    std::uint32_t clock_hz = 16000000;  // clock domain whose cycles stamp this signal's events
    bool characters = false;            // an 8-bit bus of characters (a UART): viewers show it as text
};

using SignalId = std::uint32_t;

// Another name for a recorded signal: a board's net ("nets.x_step" for
// uno.PD2) or label ("labels.heater_0"). Writers show it beside the signal
// with the same values (in VCD, a second $var with the same identifier code),
// so it costs no events.
struct SignalAlias {
    SignalId target;
    std::string scope;
    std::string name;
};

struct TimelineEvent {
    Cycle cycle;
    SignalId signal;
    union {
        std::uint64_t bits;
        double real;
    } value;
};

class Timeline {
public:
    // Registers a signal; ids are dense and in registration order, which is also
    // the order writers list signals in. Throws std::invalid_argument (one line
    // naming the signal) for an empty scope or name, whitespace in either (VCD
    // separates tokens by whitespace), a Wire wider than 1 bit, a Bus width
    // outside 1..64, a zero clock, or a scope+name registered before.
    SignalId add_signal(SignalInfo info);

    // Record blindly: writers drop events that repeat a signal's value. For a
    // Wire any nonzero `bits` is 1; for a Bus bits above `width` are ignored.
    // Events held in memory at most (24 bytes each: 1.2 GB): comparisons and
    // reports need the whole timeline; a run that records more drops the
    // rest and says so (overflowed()) instead of exhausting memory. A streamed
    // VCD (VcdStream) takes the events as the run goes and never gets here.
    static constexpr std::size_t kMaxHeldEvents = 50'000'000;

    void record(SignalId id, Cycle cycle, std::uint64_t bits) {
        if (events_.size() >= limit_ && !make_room()) [[unlikely]] return;
        TimelineEvent e{cycle, id, {}};
        e.value.bits = bits;
        events_.push_back(e);
    }
    void record_real(SignalId id, Cycle cycle, double value) {
        if (events_.size() >= limit_ && !make_room()) [[unlikely]] return;
        TimelineEvent e{cycle, id, {}};
        e.value.real = value;
        events_.push_back(e);
    }
    // Events not recorded because kMaxHeldEvents were held.
    std::uint64_t dropped() const { return dropped_; }
    bool overflowed() const { return dropped_ != 0; }
    // "the run recorded more than ... events ..." (one line), for callers to report.
    std::string overflow_message() const;
    void set_max_held_events(std::size_t n) {
        max_held_ = n;
        limit_ = sink_ ? sink_limit() : max_held_;
    }

    // Streaming to a consumer that keeps what it needs (check's comparison):
    // every `batch_events` events recorded are handed to `sink` in record
    // order and forgotten, so the timeline holds at most that many.
    // flush_stream() hands over the rest. The held-events cap counts what
    // was handed over (the consumer holds it): past it events are dropped
    // and counted as without a sink. Not with keep_when_taken.
    using EventSink = std::function<void(const std::vector<TimelineEvent>&)>;
    void stream_to(EventSink sink, std::size_t batch_events = std::size_t{1} << 16);
    void flush_stream();

    const std::vector<SignalInfo>& signals() const { return signals_; }
    // Events in the order they were recorded. Within one clock domain this is
    // cycle order; across domains (several MCUs) order may differ by up to one
    // instruction, so writers that need global order sort by time.
    const std::vector<TimelineEvent>& events() const { return events_; }

    // Adds `scope.name` as another name of `target`. Same checks as
    // add_signal (no empty or whitespace names, no name used twice).
    void add_alias(SignalId target, const std::string& scope, const std::string& name);
    const std::vector<SignalAlias>& aliases() const { return aliases_; }

    // Returns the signal with that scope and name, or -1.
    long find(const std::string& scope, const std::string& name) const;

    // Streaming (VcdStream): hands over the events recorded since the last
    // take and forgets them - all but those of the signals keep_when_taken()
    // names, which events() goes on holding (before the newer ones) for a
    // reader at the end such as the HTML report. events() then holds only
    // those and what came after.
    std::vector<TimelineEvent> take_events() {
        std::vector<TimelineEvent> out;
        take_events_into(out);
        return out;
    }
    // The same into `out` (its contents dropped); without kept signals the
    // timeline records into `out`'s storage afterwards, so a streaming
    // consumer that keeps one buffer allocates nothing per take.
    void take_events_into(std::vector<TimelineEvent>& out) {
        taken_ += events_.size() - kept_;
        if (keep_.empty()) {
            out.clear();
            out.swap(events_);
            return;
        }
        out.assign(events_.begin() + static_cast<std::ptrdiff_t>(kept_), events_.end());
        std::size_t kept = kept_;
        for (std::size_t i = kept_; i < events_.size(); ++i) {
            if (events_[i].signal < keep_.size() && keep_[events_[i].signal]) events_[kept++] = events_[i];
        }
        events_.resize(kept);
        kept_ = kept;
    }
    // Signals whose events a take leaves in events() (by SignalId; ids past
    // the end are not kept). Set before the first take.
    void keep_when_taken(std::vector<bool> keep) { keep_ = std::move(keep); }
    // Every event recorded, taken or not.
    std::uint64_t recorded_count() const { return taken_ + events_.size() - kept_; }

    // Avoids reallocation on the hot path when the caller knows the run's size.
    void reserve_events(std::size_t count) { events_.reserve(count); }

private:
    std::vector<SignalInfo> signals_;
    std::vector<TimelineEvent> events_;
    std::vector<SignalAlias> aliases_;
    std::uint64_t taken_ = 0;
    std::vector<bool> keep_;  // keep_when_taken
    std::size_t kept_ = 0;    // events_[0, kept_) were taken and kept
    std::uint64_t dropped_ = 0;
    std::size_t max_held_ = kMaxHeldEvents;
    std::size_t limit_ = kMaxHeldEvents;  // max_held_, or sink_limit() when streaming
    // The sink's batch, or less where it would pass the cap.
    std::size_t sink_limit() const { return taken_ >= max_held_ ? 0 : std::min<std::uint64_t>(sink_batch_, max_held_ - taken_); }
    EventSink sink_;
    std::size_t sink_batch_ = 0;
    // At limit_: hands the events to the sink (true: record on), or counts a drop.
    bool make_room();
    std::map<std::pair<std::string, std::string>, SignalId> index_;  // (scope, name) -> id
};

}  // namespace avrbench
