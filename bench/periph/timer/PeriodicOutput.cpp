#include "periph/timer/PeriodicOutput.hpp"

namespace avrbench {

Cycle PeriodicWave::high_cycles_per_period() const { return high_cycles_until(start + period); }

Cycle PeriodicWave::high_cycles_until(Cycle c) const {
    if (c <= start) return 0;
    const Cycle whole = (c - start) / period;
    const Cycle into = (c - start) % period;
    Cycle per_period = 0, partial = 0;
    Cycle from = 0;
    bool level = start_level;
    for (std::size_t i = 0; i < edge_count; ++i) {
        const Cycle to = edges[i].offset;
        if (level) {
            per_period += to - from;
            if (into > from) partial += (into < to ? into : to) - from;
        }
        from = to;
        level = edges[i].level;
    }
    if (level) {
        per_period += period - from;
        if (into > from) partial += into - from;
    }
    return whole * per_period + partial;
}

bool PeriodicWave::level_at(Cycle c) const {
    const Cycle into = c <= start ? 0 : (c - start) % period;
    bool level = start_level;
    for (std::size_t i = 0; i < edge_count && edges[i].offset <= into; ++i) level = edges[i].level;
    return level;
}

}  // namespace avrbench
