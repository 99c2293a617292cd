#include "core/Lockstep.hpp"

#include <algorithm>
#include <limits>

namespace avrbench {
namespace {

__extension__ using u128 = unsigned __int128;  // exact products of 64-bit cycles and 32-bit clocks

// a_cycle / a.f  <  b_cycle / b.f, exactly.
bool earlier(const Mcu& a, Cycle a_cycle, const Mcu& b, Cycle b_cycle) {
    if (a.frequency_hz() == b.frequency_hz()) return a_cycle < b_cycle;  // the usual board: no 128-bit products
    return static_cast<u128>(a_cycle) * b.frequency_hz() < static_cast<u128>(b_cycle) * a.frequency_hz();
}

// The first cycle of `mcu` at or after `other_cycle` of `other`.
Cycle cycle_at_time_of(const Mcu& mcu, const Mcu& other, Cycle other_cycle) {
    if (other_cycle == ~Cycle{0} || mcu.frequency_hz() == other.frequency_hz()) return other_cycle;
    const u128 num = static_cast<u128>(other_cycle) * mcu.frequency_hz();
    const u128 den = other.frequency_hz();
    const u128 c = (num + den - 1) / den;
    return c > ~Cycle{0} ? ~Cycle{0} : static_cast<Cycle>(c);
}

}  // namespace

Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps) {
    const u128 num = static_cast<u128>(time_ps) * mcu.frequency_hz();
    return static_cast<Cycle>((num + kPsPerSecond - 1) / kPsPerSecond);
}

std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle) {
    return static_cast<std::uint64_t>(static_cast<u128>(cycle) * kPsPerSecond / mcu.frequency_hz());
}

Lockstep::~Lockstep() {
    for (Mcu* m : mcus_) m->set_peer_sync(nullptr);
}

void Lockstep::add(Mcu& mcu) {
    mcus_.push_back(&mcu);
    // One MCU needs no synchronising; with two, every MCU reports to us.
    if (mcus_.size() >= 2) {
        for (Mcu* m : mcus_) m->set_peer_sync(this);
    }
}

void Lockstep::couple(const Mcu& a, const Mcu& b) {
    if (&a == &b) return;
    coupled_.insert({&a, &b});
    coupled_.insert({&b, &a});
}

bool Lockstep::coupled(const Mcu& a, const Mcu& b) const { return !coupled_.empty() && coupled_.count({&a, &b}) != 0; }

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

void Lockstep::reach(Mcu& mcu) {
    Mcu* const runner = running_;
    if (runner == nullptr || &mcu == runner) return;
    // Whatever changes now may wake `mcu` or change its outputs: every
    // horizon is worked out again after the runner's instruction.
    runner->request_yield();
    if (mcu.halted() || mcu.in_run() || !mcu.dormant()) return;
    const Cycle target = cycle_at_time_of(mcu, *runner, runner->cycle());
    if (mcu.cycle() >= target) return;
    ++catch_ups_;
    running_ = &mcu;
    if (mcu.run_until(target) == StopReason::Requested) requested_stop_ = true;
    running_ = runner;
}

StopReason Lockstep::run_until_ps(std::uint64_t end_ps) {
    requested_stop_ = false;
    end_cycles_.resize(mcus_.size());
    for (std::size_t k = 0; k < mcus_.size(); ++k) end_cycles_[k] = cycle_at_ps(*mcus_[k], end_ps);
    for (;;) {
        // The core furthest behind, and the earliest horizon of the others.
        Mcu* behind = nullptr;
        Cycle behind_end = 0;
        for (std::size_t k = 0; k < mcus_.size(); ++k) {
            Mcu* m = mcus_[k];
            if (m->halted() || m->cycle() >= end_cycles_[k]) continue;
            if (behind == nullptr || earlier(*m, m->cycle(), *behind, behind->cycle())) {
                behind = m;
                behind_end = end_cycles_[k];
            }
        }
        if (behind == nullptr) break;
        Cycle target = behind_end;
        for (Mcu* m : mcus_) {
            if (m == behind || m->halted()) continue;
            const bool may_pass = lookahead_ && m->dormant() && !coupled(*behind, *m);
            const Cycle horizon = may_pass ? m->next_event_cycle() : m->cycle();
            target = std::min(target, cycle_at_time_of(*behind, *m, horizon));
        }
        // At least one instruction, or two cores at the same time would never move.
        target = std::max(target, behind->cycle() + 1);
        running_ = behind;
        const StopReason r = behind->run_until(target);
        running_ = nullptr;
        if (r == StopReason::Requested || requested_stop_) return StopReason::Requested;
    }
    for (const Mcu* m : mcus_) {
        if (!m->halted()) return StopReason::ReachedTarget;
    }
    return StopReason::Halted;
}

}  // namespace avrbench
