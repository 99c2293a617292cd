#include "core/Lockstep.hpp"

#include <limits>

namespace avrbench {
namespace {

__extension__ using u128 = unsigned __int128;  // exact products of 64-bit cycles and 32-bit clocks

// a.cycle / a.f  <  b.cycle / b.f, exactly.
bool earlier(const Mcu& a, const Mcu& b) {
    return static_cast<u128>(a.cycle()) * b.frequency_hz() < static_cast<u128>(b.cycle()) * a.frequency_hz();
}

// The first cycle of `mcu` at or after the current time of `other`.
Cycle cycle_at_time_of(const Mcu& mcu, const Mcu& other) {
    const u128 num = static_cast<u128>(other.cycle()) * mcu.frequency_hz();
    const u128 den = other.frequency_hz();
    return static_cast<Cycle>((num + den - 1) / den);
}

}  // namespace

Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps) {
    const u128 num = static_cast<u128>(time_ps) * mcu.frequency_hz();
    return static_cast<Cycle>((num + kPsPerSecond - 1) / kPsPerSecond);
}

std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle) {
    return static_cast<std::uint64_t>(static_cast<u128>(cycle) * kPsPerSecond / mcu.frequency_hz());
}

std::uint64_t Lockstep::now_ps() const {
    // The running MCU furthest behind; once all have halted, the last to halt.
    std::uint64_t now = std::numeric_limits<std::uint64_t>::max(), halted_at = 0;
    for (const Mcu* m : mcus_) {
        const std::uint64_t t = ps_at_cycle(*m, m->cycle());
        if (m->halted()) halted_at = std::max(halted_at, t);
        else now = std::min(now, t);
    }
    return now == std::numeric_limits<std::uint64_t>::max() ? halted_at : now;
}

StopReason Lockstep::run_until_ps(std::uint64_t end_ps) {
    for (;;) {
        // The core furthest behind, and the one just ahead of it.
        Mcu* behind = nullptr;
        Mcu* next = nullptr;
        for (Mcu* m : mcus_) {
            if (m->halted() || m->cycle() >= cycle_at_ps(*m, end_ps)) continue;
            if (behind == nullptr || earlier(*m, *behind)) {
                next = behind;
                behind = m;
            } else if (next == nullptr || earlier(*m, *next)) {
                next = m;
            }
        }
        if (behind == nullptr) break;
        Cycle target = cycle_at_ps(*behind, end_ps);
        if (next != nullptr) {
            // At least one instruction, or two cores at the same time would
            // never move.
            target = std::min(target, std::max(cycle_at_time_of(*behind, *next), behind->cycle() + 1));
        }
        if (behind->run_until(target) == StopReason::Requested) return StopReason::Requested;
    }
    for (const Mcu* m : mcus_) {
        if (!m->halted()) return StopReason::ReachedTarget;
    }
    return StopReason::Halted;
}

}  // namespace avrbench
