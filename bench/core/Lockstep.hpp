// Several MCUs on one board advanced in simulated-time order, exactly.
//
// The MCU furthest behind runs. It may run up to the horizon of every other
// MCU: the time of one that is awake (so two awake cores stay within one
// instruction of each other, as before), or the next cycle timer of one that
// is dormant (asleep, no interrupt on its way: nothing about it changes
// before that timer unless something outside wakes it). Everything outside
// an MCU that can change what it sees - a net delivering a level, the TWI
// bus - calls Mcu::before_external_change() first; the lockstep then brings
// that MCU, if it is dormant and behind, up to the running MCU's time (an
// exact jump: it has no event before its horizon) and makes the running MCU
// yield after its instruction, so the horizons are worked out again. Boards
// whose MCUs sleep between interrupts (seed 001's five) thus run each core
// in long stretches instead of one instruction at a time.
//
// Parts joined by ports call each other directly, so each such group of parts
// has one clock (boards/Board.cpp); MCUs a group must share anyway (two MCUs
// sampling one part's analog outputs) are coupled() and never run ahead of
// each other. Clocks may differ (times compare as exact rationals
// cycle/frequency).
#pragma once

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "core/Mcu.hpp"

namespace avrbench {

class Lockstep final : public PeerSync {
public:
    Lockstep() = default;
    ~Lockstep() override;
    Lockstep(const Lockstep&) = delete;
    Lockstep& operator=(const Lockstep&) = delete;

    void add(Mcu& mcu);
    const std::vector<Mcu*>& mcus() const { return mcus_; }
    // `a` and `b` never run ahead of each other's present time.
    void couple(const Mcu& a, const Mcu& b);
    // Off: every MCU's horizon is its present time (strict lockstep), for
    // tests that compare the two.
    void set_lookahead(bool on) { lookahead_ = on; }

    // Runs every MCU to `end_ps` picoseconds of simulated time (each stops at
    // the first instruction boundary at or after it). Halted MCUs drop out.
    // Returns Requested as soon as any callback asked one MCU to stop.
    StopReason run_until_ps(std::uint64_t end_ps);
    // From a callback inside a run (a pin or a line someone waits for): the
    // present run_until_ps returns Requested after the running MCU's
    // instruction. Outside a run it does nothing.
    void request_stop() {
        if (running_ == nullptr) return;
        requested_stop_ = true;
        running_->request_stop();
    }

    // Whole-board simulated time in picoseconds: the time of the MCU furthest behind.
    std::uint64_t now_ps() const;

    // PeerSync: `mcu` is about to see a change made by the running MCU.
    void reach(Mcu& mcu) override;

    // Catch-up jumps made (dormant MCUs brought forward to a running one).
    std::uint64_t catch_ups() const { return catch_ups_; }

private:
    bool coupled(const Mcu& a, const Mcu& b) const;
    std::vector<Mcu*> mcus_;
    std::vector<Cycle> end_cycles_;  // run_until_ps's end, per MCU
    std::set<std::pair<const Mcu*, const Mcu*>> coupled_;
    bool lookahead_ = true;
    Mcu* running_ = nullptr;
    bool requested_stop_ = false;  // a catch-up run was stopped by a callback
    std::uint64_t catch_ups_ = 0;
};

// Cycle of `mcu` at or after `time_ps` picoseconds.
Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps);
// Picoseconds at `cycle` of `mcu`, rounded down.
std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle);

}  // namespace avrbench
