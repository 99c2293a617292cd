// One step of the core, as Debian's simavr 1.6 (1.6+dfsg-3) takes it in
// avr_callback_run_raw (simavr/sim/sim_avr.c), with two changes: the cycle
// timers are processed only when the first is due, and an interrupt is served
// one instruction after SEI/RETI/OUT SREG, not two (see finish()). This is the one place in
// the bench that mirrors simavr's run loop; it must follow that function
// line by line (re-check it when the simavr version changes).
//
// Why it is exact: avr_cycle_timer_process (sim_cycle_timers.c), when no
// timer is due, only returns `when - cycle` of the first timer and sets
// run_cycle_count = min(run_cycle_limit, that) = 1, because run_cycle_limit
// is 1 (set at reset; nothing in the bench changes it) and avr_run_one then
// never batches instructions. With any other limit, or while simavr has
// swapped its run callback (the watchdog does, from inside a cycle timer, for
// one step, to reset the core: avr_watchdog.c; gdb does too), the step is
// simavr's own avr_run. Both are re-checked after every due timer and every
// avr_run; a stepper is made per run and must not outlive it. Tests: RunLoop.* run every workload both ways and
// compare cycle, PC, SREG, registers, RAM and the recorded timeline.
//
// Why it is faster: avr_run calls the run loop through a function pointer
// and the timer pool through a call on every instruction; here both are
// inline or skipped, and Mcu::run_until's fast path reduces a step with
// nothing due and nothing pending to avr_run_one and the new PC, handing
// anything else to finish() (docs/PERFORMANCE.md).
#pragma once

#include <algorithm>

extern "C" {
#include <sim_avr.h>
#include <sim_core.h>
#include <sim_cycle_timers.h>
#include <sim_interrupts.h>
}

#include "mcu/PredecodedCore.hpp"

namespace avrbench {

class SimavrStepper {
public:
    // With `core`, an instruction is PredecodedCore::run_one (avr_run_one's
    // contract, proven equal); without, simavr's avr_run_one.
    explicit SimavrStepper(avr_t* avr, PredecodedCore* core = nullptr) : avr_(avr), core_(core) { recheck(); }

    // One instruction: avr_run_one or the predecoded core.
    __attribute__((always_inline)) avr_flashaddr_t run_one() {
        return core_ != nullptr ? core_->run_one(avr_) : avr_run_one(avr_);
    }

    __attribute__((always_inline)) int step() {
        avr_t* const avr = avr_;
        if (__builtin_expect(!raw_, 0)) {
            const int state = avr_run(avr);
            recheck();
            return state;
        }
        avr_flashaddr_t new_pc = avr->pc;
        if (avr->state == cpu_Running) new_pc = run_one();
        return finish(new_pc);
    }

    // The reference step (McuOptions::reference_run_loop): avr_callback_run_raw
    // line by line - the cycle timers processed on every step - with the
    // datasheet's interrupt timing of finish(); tests compare the fast loop
    // with it.
    int reference_step() {
        avr_t* const avr = avr_;
        if (!raw_) {
            const int state = avr_run(avr);
            recheck();
            return state;
        }
        avr_flashaddr_t new_pc = avr->pc;
        if (avr->state == cpu_Running) new_pc = avr_run_one(avr);
        return finish(new_pc, true);
    }

    // True when the next steps may take the fast path of Mcu::run_until:
    // simavr's raw loop, the core running, no interrupt on its way.
    bool fast_path_open() const {
        return raw_ && avr_->state == cpu_Running && avr_->interrupt_state == 0;
    }

    // The rest of step() after avr_run_one returned `new_pc`: the cycle
    // timers (only when the first is due), the new PC, sleep, interrupts.
    __attribute__((always_inline)) int finish(avr_flashaddr_t new_pc, bool every_step = false) {
        avr_t* const avr = avr_;
        // avr_cycle_timer_process, or (nothing due) what it would return.
        const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
        const bool due = every_step || first == nullptr || first->when <= avr->cycle;
        avr_cycle_count_t sleep = 0;
        if (due) {
            sleep = avr_cycle_timer_process(avr);
            recheck();  // a timer may have swapped the run callback (the watchdog)
        }

        avr->pc = new_pc;
        const int state = avr->state;
        if (state == cpu_Sleeping) {
            if (!avr->sreg[S_I]) {
                if (avr->log) AVR_LOG(avr, LOG_TRACE, "simavr: sleeping with interrupts off, quitting gracefully\n");
                avr->state = cpu_Done;
                return cpu_Done;
            }
            if (!due) sleep = first->when - avr->cycle;
            if (horizon_ != kNoHorizon) {
                // The sleep a cycle timer at the horizon would give (simavr
                // sleeps to the first timer): up to it, or, once reached,
                // one cycle - that timer would have fired in this step and
                // re-armed itself one cycle on, to keep the jump short.
                const avr_cycle_count_t to_horizon = horizon_ > avr->cycle ? horizon_ - avr->cycle : 1;
                sleep = avr->cycle_timers.timer == nullptr ? to_horizon : std::min(sleep, to_horizon);
            }
            avr->sleep(avr, sleep);
            avr->cycle += 1 + sleep;
        }
        if (state == cpu_Running || state == cpu_Sleeping) {
            if (avr->interrupt_state) {
                // The one departure from simavr's loop (a datasheet fix,
                // fixes/InterruptTiming.cpp item 2): the step that set I (SEI,
                // RETI, OUT SREG) leaves interrupt_state at -2, which serves
                // a pending interrupt only after the second instruction
                // that follows; the datasheet serves it after the first
                // ("the instruction following SEI will be executed before any
                // pending interrupts"). At -1 here, an interrupt raised while
                // that one instruction runs is served right after it - before
                // the CLI of `sei; nop; cli` (Klipper's irq_wait).
                if (avr->interrupt_state == -2) avr->interrupt_state = -1;
                avr_service_interrupts(avr);
            }
        }
        return avr->state;
    }

    // Mcu::run_until's target: a sleep jumps no further than a cycle timer
    // there would let it (simavr's sleep goes to the first timer), without
    // a timer registered and cancelled on every run.
    void set_horizon(avr_cycle_count_t horizon) { horizon_ = horizon; }

private:
    static constexpr avr_cycle_count_t kNoHorizon = ~avr_cycle_count_t{0};
    void recheck() { raw_ = avr_->run == &avr_callback_run_raw && avr_->run_cycle_limit == 1; }

    avr_t* avr_;
    PredecodedCore* core_;
    avr_cycle_count_t horizon_ = kNoHorizon;
    bool raw_ = false;
};

}  // namespace avrbench
