// Several MCUs on one board advanced in simulated-time order.
//
// The MCU furthest behind runs until it passes the next one, so at any moment
// the skew between any two cores is at most one instruction (5 cycles) of the
// one that ran last; a sleeping core is stopped at that horizon too instead of
// jumping to its own next event. Clocks may differ (times compare as exact
// rationals cycle/frequency).
#pragma once

#include <vector>

#include "core/Mcu.hpp"

namespace avrbench {

class Lockstep {
public:
    void add(Mcu& mcu) { mcus_.push_back(&mcu); }
    const std::vector<Mcu*>& mcus() const { return mcus_; }

    // Runs every MCU to `end_ps` picoseconds of simulated time (each stops at
    // the first instruction boundary at or after it). Halted MCUs drop out.
    // Returns Requested as soon as any callback asked one MCU to stop.
    StopReason run_until_ps(std::uint64_t end_ps);

    // Whole-board simulated time in picoseconds: the time of the MCU furthest behind.
    std::uint64_t now_ps() const;

private:
    std::vector<Mcu*> mcus_;
};

// Cycle of `mcu` at or after `time_ps` picoseconds.
Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps);
// Picoseconds at `cycle` of `mcu`, rounded down.
std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle);

}  // namespace avrbench
