// Callbacks at simulated times of one MCU.
//
// Built on one simavr cycle timer armed at the earliest pending event, so a
// sleeping core fast-forwards straight to the next event (simavr's sleep path
// jumps the cycle counter to its next cycle timer) and nothing ever waits on
// the wall clock.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <vector>

#include "core/Time.hpp"

struct avr_t;

namespace avrbench {

class Scheduler {
public:
    using Callback = std::function<void(Cycle scheduled_cycle)>;

    explicit Scheduler(avr_t* avr) : avr_(avr) {}
    Scheduler(const Scheduler&) = delete;
    Scheduler& operator=(const Scheduler&) = delete;
    ~Scheduler();

    // Runs `fn` once the MCU's cycle counter reaches `cycle` (at the first
    // instruction boundary at or after it; an instruction may take up to 5
    // cycles). A cycle in the past runs at the next boundary.
    void at(Cycle cycle, Callback fn);
    void after(Cycle delay_cycles, Callback fn);

    std::size_t pending() const { return queue_.size(); }

    // simavr's avr_reset() drops every cycle timer; the owner calls this after
    // a reset (watchdog) so pending events still fire.
    void rearm();

private:
    // The queue orders small records; the callbacks stay where they were
    // put (a deque: a callback may schedule more while it runs), so the heap
    // moves no std::function about.
    struct Event {
        Cycle cycle;
        std::uint64_t sequence;  // keeps same-cycle events in registration order
        std::uint32_t slot;      // its callback in slots_
    };
    struct Later {
        bool operator()(const Event& a, const Event& b) const {
            return a.cycle != b.cycle ? a.cycle > b.cycle : a.sequence > b.sequence;
        }
    };
    static std::uint64_t on_timer(avr_t* avr, std::uint64_t when, void* param);
    void arm();

    avr_t* avr_;
    std::vector<Event> queue_;  // a heap under Later: the earliest first
    std::deque<Callback> slots_;
    std::vector<std::uint32_t> free_slots_;
    std::uint64_t next_sequence_ = 0;
    bool dispatching_ = false;
    Cycle armed_for_ = 0;
    bool armed_ = false;
};

}  // namespace avrbench
