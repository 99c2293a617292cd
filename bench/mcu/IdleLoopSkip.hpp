// Exact fast-forward of idle loops.
//
// A firmware waiting for something (a UART flag, TWINT, a flag its ISR
// sets, grbl's and Marlin's main loops with nothing to do) runs the same
// instructions over and over in the same state until an event changes it.
// In simavr every such event is a cycle timer (timers, UART, ADC, the
// bench's scheduler and the run's horizon) or an I/O callback. So when one
// pass of a loop, watched instruction by instruction, ends in exactly the
// state it began (PC, registers, SREG, SP, every byte it wrote), touched no
// I/O register with a callback (their values may depend on the cycle or
// have side effects), and no interrupt is pending, every further pass up to
// the first cycle timer is identical: the skipper adds whole passes to the
// cycle counter, stopping at the last pass boundary before that timer, so
// the timer fires at the same instruction boundary and the same cycle as it
// would have. Tests: RunLoop.* (every firmware, full timelines and RAM,
// with and without skipping), IdleLoopSkip.*.
//
// Count-down delay loops (`sbiw r24,1; brne`, `dec r; brne`) are not fixed
// points, but their passes differ only in the counter: those are skipped
// arithmetically, leaving the last pass before the event to run for real.
//
// Cost when nothing is idle: a countdown per instruction, and one watched
// pass every few thousand instructions (backing off while passes fail).
#pragma once

#include <cstdint>
#include <vector>

struct avr_t;

namespace avrbench {

class IdleLoopSkipper {
public:
    explicit IdleLoopSkipper(avr_t* avr);

    // Called before an instruction runs, every `n` instructions where n is
    // what the previous call returned (1 while a pass is being watched).
    // Never jumps to or past `run_end_cycle`, where the caller's loop stops
    // (its horizon timer says the same, but a reset drops every timer).
    std::uint32_t tick(std::uint64_t run_end_cycle);

    // True while it waits for the loop its last jump skipped, after the
    // event that ended it, and a RETI would leave SP at `sp_after`, the
    // loop's level: the run loop then ticks it right after that RETI.
    bool look_after_interrupt_return(std::uint16_t sp_after) const;

    std::uint64_t jumps() const { return jumps_; }
    std::uint64_t cycles_skipped() const { return cycles_skipped_; }

private:
    struct Written {
        std::uint16_t address;
        std::uint8_t value_before;
    };
    enum class Access : std::uint8_t { Fine, Refuse };

    std::uint32_t start_watching(std::uint64_t run_end_cycle);
    // A count-down delay loop at PC: skips its passes up to the next event.
    enum class DelayLoop : std::uint8_t { None, Skipped, EventTooClose, AtItsBranch };
    DelayLoop skip_delay_loop(std::uint64_t run_end_cycle);
    std::uint32_t give_up();
    // Checks the instruction at PC before it runs; records what it will write.
    Access inspect_next_instruction();
    bool note_read(std::uint32_t address) const;
    bool note_write(std::uint32_t address);
    bool back_where_it_started() const;

    avr_t* avr_;
    std::vector<bool> readable_io_;  // I/O with a read callback that is a pure function of the module's state
    bool watching_ = false;
    std::uint32_t head_pc_ = 0;
    std::uint64_t head_cycle_ = 0;
    std::uint64_t timer_cycle_ = 0;  // the first cycle timer when the watch began
    unsigned timer_count_ = 0;       // and how many there were
    std::uint8_t registers_[32] = {};
    std::uint8_t sreg_[8] = {};
    std::uint16_t sp_ = 0;
    std::vector<Written> written_;
    std::uint32_t watched_ = 0;
    std::uint32_t backoff_ = 0;
    bool in_delay_loop_ = false;  // the last look found a delay loop
    std::uint16_t jump_sp_ = 0;   // SP of the loop the last jump skipped
    unsigned after_jump_looks_ = ~0u;  // looks since then (kAfterJumpLooks and up: none pending)
    unsigned delay_misses_ = 0;   // looks since that found none

    std::uint64_t jumps_ = 0;
    std::uint64_t cycles_skipped_ = 0;
};

}  // namespace avrbench
