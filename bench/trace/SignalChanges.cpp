#include "trace/SignalChanges.hpp"

#include <algorithm>
#include <cstring>

namespace avrbench {

void SignalChanges::new_chunk() {
    keys_.push_back(std::make_unique_for_overwrite<std::uint64_t[]>(kChunk));
    if (kind_ != SignalKind::Wire) values_.push_back(std::make_unique_for_overwrite<std::uint64_t[]>(kChunk));
    chunk_fill_ = 0;
}

void SignalChanges::set(std::size_t i, Cycle cycle, std::uint64_t bits) {
    std::uint64_t& k = keys_[i >> kChunkShift][i & (kChunk - 1)];
    if (kind_ == SignalKind::Wire) {
        k = (cycle << 1) | (bits != 0 ? 1u : 0u);
    } else {
        k = cycle;
        values_[i >> kChunkShift][i & (kChunk - 1)] = bits;
    }
}

void SignalChanges::truncate(std::size_t n) {
    size_ = n;
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    keys_.resize(chunks);
    if (kind_ != SignalKind::Wire) values_.resize(chunks);
    chunk_fill_ = n - (chunks == 0 ? 0 : (chunks - 1) * kChunk);
}

bool SignalChanges::same_value(std::uint64_t a, std::uint64_t b) const {
    if (kind_ != SignalKind::Real) return a == b;
    double x = 0, y = 0;
    std::memcpy(&x, &a, sizeof x);
    std::memcpy(&y, &b, sizeof y);
    return x == y;
}

void SignalChanges::finish() {
    bool sorted = true;
    for (std::size_t i = 1; i < size_ && sorted; ++i) sorted = cycle(i - 1) <= cycle(i);
    if (!sorted) {
        // Events of one signal come in cycle order from one clock domain; this
        // is the rare case, so a flat copy is acceptable here.
        std::vector<TimelineEvent> flat;
        flat.reserve(size_);
        for (std::size_t i = 0; i < size_; ++i) flat.push_back((*this)[i]);
        std::stable_sort(flat.begin(), flat.end(), [](const TimelineEvent& a, const TimelineEvent& b) { return a.cycle < b.cycle; });
        for (std::size_t i = 0; i < size_; ++i) set(i, flat[i].cycle, flat[i].value.bits);
    }
    // In place, as changes_of's dedupe: `kept` entries are the result so far.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < size_; ++i) {
        const Cycle c = cycle(i);
        const std::uint64_t v = bits(i);
        if (kept > 0 && cycle(kept - 1) == c) {
            set(kept - 1, c, v);
            if (kept >= 2 && same_value(bits(kept - 2), v)) --kept;
            continue;
        }
        if (kept > 0 && same_value(bits(kept - 1), v)) continue;
        set(kept++, c, v);
    }
    truncate(kept);
}

TimelineChanges timeline_changes(const Timeline& timeline) {
    TimelineChanges out;
    out.signals = timeline.signals();
    out.changes.reserve(out.signals.size());
    for (const SignalInfo& s : out.signals) out.changes.emplace_back(s.kind);
    for (const TimelineEvent& e : timeline.events()) {
        if (e.signal < out.changes.size()) out.changes[e.signal].add(e);
    }
    for (auto& c : out.changes) c.finish();
    return out;
}

}  // namespace avrbench
