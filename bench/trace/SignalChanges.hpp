// Signals' changes held compactly, for comparing long runs against their
// goldens: a wire's event is one 8-byte word (its cycle and level packed), a
// bus's or real's two; held in fixed chunks, so growing never copies what is
// held nor reserves twice what is needed (a 5 M-edge wire is 40 MB, not the
// 120 MB of TimelineEvents and up to twice that while a vector grows).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "trace/Timeline.hpp"

namespace avrbench {

class SignalChanges {
public:
    explicit SignalChanges(SignalKind kind = SignalKind::Wire) : kind_(kind) {}

    SignalKind kind() const { return kind_; }

    // Appends an event as recorded: any order, repeats allowed, until finish().
    // A real's value is the double's bits (TimelineEvent::value).
    void add(Cycle cycle, std::uint64_t bits) {
        if (chunk_fill_ == kChunk || keys_.empty()) new_chunk();
        keys_.back()[chunk_fill_] = kind_ == SignalKind::Wire ? (cycle << 1) | (bits != 0 ? 1u : 0u) : cycle;
        if (kind_ != SignalKind::Wire) values_.back()[chunk_fill_] = bits;
        ++chunk_fill_;
        ++size_;
    }
    void add(const TimelineEvent& e) { add(e.cycle, e.value.bits); }

    // Makes what was added the signal's changes, as changes_of() does: in
    // cycle order (stable), at one cycle the last value recorded, repeats of
    // the previous value dropped.
    void finish();

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    Cycle cycle(std::size_t i) const { return kind_ == SignalKind::Wire ? key(i) >> 1 : key(i); }
    std::uint64_t bits(std::size_t i) const { return kind_ == SignalKind::Wire ? key(i) & 1u : value(i); }
    // The event (its signal field 0).
    TimelineEvent operator[](std::size_t i) const {
        TimelineEvent e{cycle(i), 0, {}};
        e.value.bits = bits(i);
        return e;
    }
    TimelineEvent front() const { return (*this)[0]; }
    TimelineEvent back() const { return (*this)[size_ - 1]; }

private:
    // 8 KiB of keys a chunk: a signal with few changes wastes at most that.
    static constexpr std::size_t kChunkShift = 10;
    static constexpr std::size_t kChunk = std::size_t{1} << kChunkShift;
    std::uint64_t key(std::size_t i) const { return keys_[i >> kChunkShift][i & (kChunk - 1)]; }
    std::uint64_t value(std::size_t i) const { return values_[i >> kChunkShift][i & (kChunk - 1)]; }
    void set(std::size_t i, Cycle cycle, std::uint64_t bits);
    void truncate(std::size_t n);
    void new_chunk();
    bool same_value(std::uint64_t a, std::uint64_t b) const;

    SignalKind kind_;
    std::vector<std::unique_ptr<std::uint64_t[]>> keys_, values_;
    std::size_t chunk_fill_ = 0;  // entries used in the last chunk
    std::size_t size_ = 0;
};

// A timeline held as each signal's changes (SignalChanges, finished).
struct TimelineChanges {
    std::vector<SignalInfo> signals;
    std::vector<SignalChanges> changes;  // by SignalId
};

// `timeline`'s events grouped by signal in one pass, each signal finished.
TimelineChanges timeline_changes(const Timeline& timeline);

}  // namespace avrbench
