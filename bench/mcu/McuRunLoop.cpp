// The Mcu running its firmware: the run loops (plain, covering, profiling,
// stopping at SLEEP), stop and yield requests, and the checks after each
// step (crash, invalid opcode, PC outside the program, stack overflow).
// Construction, memory and pins: Mcu.cpp.
#include "mcu/Mcu.hpp"

#include <cstdio>
#include <cstring>

extern "C" {
#include <sim_avr.h>
#include <sim_cycle_timers.h>
#include <sim_interrupts.h>
}

#include "core/UserStop.hpp"
#include "mcu/DebugHook.hpp"
#include "mcu/IdleLoopSkip.hpp"
#include "mcu/SimavrStep.hpp"
#include "mcu/TimingProfile.hpp"
#include "periph/interrupts/Interrupts.hpp"
#include "periph/watchdog/WatchdogWatch.hpp"

namespace avrbench {
namespace {

// Due at once: a stop requested from inside an instruction (an I/O hook)
// ends run_until's fast path, which looks only at the first timer.
avr_cycle_count_t stop_timer(avr_t*, avr_cycle_count_t, void*) { return 0; }

bool is_out_to(const avr_t* avr, std::uint32_t pc_bytes, unsigned io_address) {
    const unsigned opcode = avr->flash[pc_bytes] | (avr->flash[pc_bytes + 1] << 8);
    // OUT A,Rr: 1011 1AAr rrrr AAAA (AVR Instruction Set Manual).
    if ((opcode & 0xF800) != 0xB800) return false;
    return (((opcode >> 5) & 0x30) | (opcode & 0x0F)) == io_address;
}

constexpr unsigned kSleepOpcode = 0x9588;  // SLEEP (AVR Instruction Set Manual)
constexpr unsigned kRetiOpcode = 0x9518;   // RETI

// avr-gcc's prologues and epilogues set SP with `out SPH`, `out SREG`,
// `out SPL`; between the SPH and SPL writes SP reads as new-high/old-low,
// which can dip below its true value. The check runs again after the SPL write.

bool sp_half_written(const avr_t* avr, std::uint32_t pc_before) {
    constexpr unsigned kSph = 0x3E, kSreg = 0x3F;
    if (is_out_to(avr, pc_before, kSph)) return true;
    return pc_before >= 2 && is_out_to(avr, pc_before, kSreg) && is_out_to(avr, pc_before - 2, kSph);
}

}  // namespace

void Mcu::request_stop() {
    stop_requested_ = true;
    real_stop_ = true;
    avr_cycle_timer_register(avr_, 0, &stop_timer, this);
}
void Mcu::request_yield() {
    if (!in_run_ || stop_requested_) return;
    stop_requested_ = true;
    avr_cycle_timer_register(avr_, 0, &stop_timer, this);
}

bool Mcu::step() {
    if (halted_) return false;
    const std::uint32_t pc_before = avr_->pc;
    SimavrStepper stepper(avr_, predecoded_.get());
    const int state = options_.reference_run_loop ? stepper.reference_step() : stepper.step();
    ++steps_;
    check_after_step(state, pc_before);
    return !halted_;
}

StopReason Mcu::run_sliced(Cycle end_cycle, const std::function<void()>& after_slice) {
    // 10 ms slices answer Ctrl-C promptly; each advances to a later cycle.
    const Cycle slice = std::clamp<Cycle>(end_cycle / 100, 1, frequency_hz() / 100 + 1);
    StopReason reason = StopReason::ReachedTarget;
    while (cycle() < end_cycle && !user_stop_requested()) {
        reason = run_until(std::min(end_cycle, cycle() + slice));
        if (after_slice) after_slice();
        if (reason == StopReason::Halted) break;
    }
    return reason;
}

bool Mcu::run_until_sleep(Cycle end_cycle, const std::function<void()>& after_slice) {
    // The run loop's own slices (fast path included), each stopping where
    // the core has executed SLEEP: no instruction-by-instruction stepping.
    const Cycle slice = std::clamp<Cycle>(end_cycle / 100, 1, frequency_hz() / 100 + 1);
    // The run loop stops in front of a SLEEP instruction; step() then
    // executes it outside the run, so its sleep jump goes to the next real
    // event (inside run_until it would stop at the slice's end).
    stop_at_sleep_ = true;
    while (cycle() < end_cycle && !sleeping() && !user_stop_requested()) {
        const StopReason reason = run_until(std::min(end_cycle, cycle() + slice));
        if (reason == StopReason::Halted) break;
        if (cycle() < end_cycle && avr_->state == cpu_Running && opcode_at(avr_, avr_->pc) == kSleepOpcode && !step()) break;
        if (after_slice) after_slice();
    }
    stop_at_sleep_ = false;
    return sleeping();
}

StopReason Mcu::run_until(Cycle target_cycle) {
    if (__builtin_expect(profiler_ != nullptr, 0)) {
        return run_coverage_ != nullptr ? run_until_impl<true, true>(target_cycle, run_coverage_)
                                        : run_until_impl<false, true>(target_cycle, nullptr);
    }
    if (run_coverage_ != nullptr) return run_until_impl<true, false>(target_cycle, run_coverage_);
    // run_until_sleep: the fast path too, stopping in front of SLEEP.
    if (__builtin_expect(stop_at_sleep_, 0)) return run_until_impl<false, false, true>(target_cycle, nullptr);
    return run_until_impl<false, false>(target_cycle, nullptr);
}

StopReason Mcu::run_until_covering(Cycle target_cycle, PcEdgeMap& edges) {
    return profiler_ != nullptr ? run_until_impl<true, true>(target_cycle, &edges)
                                : run_until_impl<true, false>(target_cycle, &edges);
}

void Mcu::enable_profile() {
    if (!profiler_) profiler_ = std::make_unique<TimingProfiler>(*this);
}

// kCover: every instruction's new PC goes into `edges` (fuzzing); without it
// the loop is the plain run loop (a separate instantiation, so the coverage
// costs the ordinary runs nothing).
template <bool kCover, bool kProfile, bool kStopAtSleep>
StopReason Mcu::run_until_impl(Cycle target_cycle, PcEdgeMap* edges) {
    stop_requested_ = false;
    real_stop_ = false;
    if (halted_) return StopReason::Halted;
    in_run_ = true;
    avr_t* const avr = avr_;
    const bool reference = options_.reference_run_loop;
    SimavrStepper stepper(avr, predecoded_.get());
    // A core that sleeps jumps to its next cycle timer, which could lie far
    // past the target: the stepper stops the jump there. (It was a cycle
    // timer at the target, registered and cancelled on every call: a tenth
    // of a five-MCU board's turn, docs/PERFORMANCE.md.)
    stepper.set_horizon(target_cycle);
    // One unsigned comparison covers PC = 0 (a reset) and PC past the program.
    const std::uint32_t code_end_minus_one = code_end_bytes_ - 1;
    // The crash oracles after an instruction; findings that halt also
    // request the stop. True when the run must stop.
    const auto check = [&](int state, std::uint32_t pc_before) -> bool {
        const std::uint32_t pc = avr->pc;
        const std::uint16_t sp = static_cast<std::uint16_t>(avr->data[R_SPL] | (avr->data[R_SPH] << 8));
        // cpu_Running = 2 and cpu_Sleeping = 3 (sim_avr.h): one comparison for both.
        static_assert(cpu_Sleeping == cpu_Running + 1);
        if (__builtin_expect(static_cast<unsigned>(state - cpu_Running) > 1 || pc - 1 >= code_end_minus_one ||
                                 pc == bad_interrupt_pc_ || sp < stack_floor_,
                             0)) {
            check_after_step(state, pc_before);
            return stop_requested_;
        }
        return false;
    };
    while (avr->cycle < target_cycle) {
        if (__builtin_expect(debug_ != nullptr, 0)) {
            debug_->before_step(*this);
            if (stop_requested_ || halted_) break;
        }
        // run_until_sleep: stop in front of SLEEP (it executes it itself).
        if (__builtin_expect(stop_at_sleep_, 0) && avr->state == cpu_Running && opcode_at(avr, avr->pc) == kSleepOpcode) break;
        // skipper_ read here, not once per run: a debugger hooked in from a
        // timer inside the run (a replay's checkpoint) drops it.
        if (__builtin_expect(--skip_countdown_ == 0, 0)) skip_countdown_ = skipper_ != nullptr ? skipper_->tick(target_cycle) : ~0u;
        const std::uint32_t pc_before = avr->pc;
        [[maybe_unused]] const Cycle cycle_before = avr->cycle;
        [[maybe_unused]] const bool was_sleeping = avr->state == cpu_Sleeping;
        const int state = __builtin_expect(reference, 0) ? stepper.reference_step() : stepper.step();
        ++steps_;
        if constexpr (kProfile) profiler_->after_step(cycle_before, was_sleeping, pc_before);
        check(state, pc_before);
        if constexpr (kCover) edges->hit(avr->pc);
        if (__builtin_expect(stop_requested_, 0)) break;
        // A profile sees every step, a debugger may stop in front of any
        // instruction: no fast path. run_until_sleep takes it only in its own
        // instantiation, which looks at every opcode there.
        if (kProfile || (!kStopAtSleep && stop_at_sleep_) || debug_ != nullptr || reference || avr->cycle >= target_cycle || !stepper.fast_path_open()) continue;

        // Fast path: while the core runs, no interrupt is on its way and
        // neither a cycle timer nor the target is due, a step of
        // SimavrStepper is one instruction (the predecoded core's run_batch,
        // or avr_run_one) and the new PC. Anything else is finished by
        // SimavrStepper::finish, as step() would, and the loop goes back to
        // the general step.
        std::uint32_t countdown = skip_countdown_;
        std::uint32_t countdown_before = countdown;
        // avr->data is fixed once the core is made (fixes/MemoryGuard grows it then).
        const std::uint8_t* const data = avr->data;
        const std::uint16_t stack_floor = stack_floor_;
        const std::uint32_t bad_interrupt_pc = bad_interrupt_pc_;
        PredecodedCore* const core = predecoded_.get();
        while (countdown > 1) {  // at 1 the general step ticks the skipper
            // In front of SLEEP: the general step above stops there.
            if constexpr (kStopAtSleep) {
                if (opcode_at(avr, avr->pc) == kSleepOpcode) break;
            }
            if (core != nullptr) {
                // The predecoded core's run of instructions it executes
                // itself: the checks below, made inside its loop. It stops
                // in front of one for avr_run_one, which the step below takes.
                const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
                const PredecodedCore::BatchLimits limits{first != nullptr ? std::min(first->when, target_cycle) : target_cycle,
                                                         countdown - 1,
                                                         code_end_minus_one,
                                                         bad_interrupt_pc,
                                                         stack_floor,
                                                         target_cycle};
                const PredecodedCore::Batch batch = core->run_batch<kCover>(avr, limits, edges);
                countdown -= batch.steps;
                if (batch.ended == PredecodedCore::Ended::TimerDue) {
                    const std::uint32_t fast_pc_before = avr->pc;
                    check(stepper.finish(batch.new_pc), fast_pc_before);
                    if constexpr (kCover) edges->hit(avr->pc);
                    // The timers fired and left the core running with
                    // nothing pending: the next batch, not the general step
                    // (which would run the same instruction the same way).
                    // A timer may have hooked a debugger in (a replay's
                    // checkpoint): then the general step.
                    if (stop_requested_ || debug_ != nullptr || stop_at_sleep_ != kStopAtSleep || avr->cycle >= target_cycle ||
                        !stepper.fast_path_open()) {
                        break;
                    }
                    continue;
                }
                if (batch.ended == PredecodedCore::Ended::CheckPc) {
                    const std::uint32_t fast_pc_before = avr->pc;
                    avr->pc = batch.new_pc;
                    check_after_step(cpu_Running, fast_pc_before);
                    if constexpr (kCover) edges->hit(batch.new_pc);
                    if (stop_requested_) break;
                    continue;
                }
                if (batch.ended == PredecodedCore::Ended::Count || countdown <= 1) continue;
                if constexpr (kStopAtSleep) {
                    if (opcode_at(avr, avr->pc) == kSleepOpcode) break;
                }
                // The skipper, waiting for the loop an interrupt left, looks
                // right after the RETI that may return to it (the general
                // step below runs the RETI, then ticks it).
                if (batch.ended == PredecodedCore::Ended::HandOver && countdown > 2 && skipper_ != nullptr &&
                    opcode_at(avr, avr->pc) == kRetiOpcode &&
                    skipper_->look_after_interrupt_return(
                        static_cast<std::uint16_t>((data[R_SPL] | (data[R_SPH] << 8)) + avr->address_size))) {
                    countdown_before -= countdown - 2;  // the steps below count turns of this loop, not the cut
                    countdown = 2;
                }
            }
            --countdown;
            // avr_run_one (or the predecoded core) leaves avr->pc alone: it still holds the PC before the instruction.
            const std::uint32_t pc = stepper.run_one();
            const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
            if (__builtin_expect(avr->cycle >= target_cycle, 0) || __builtin_expect(first != nullptr && first->when <= avr->cycle, 0) ||
                __builtin_expect(avr->state != cpu_Running, 0) ||
                __builtin_expect(avr->interrupt_state != 0, 0)) {
                const std::uint32_t fast_pc_before = avr->pc;
                check(stepper.finish(pc), fast_pc_before);
                if constexpr (kCover) edges->hit(avr->pc);
                break;
            }
            const std::uint16_t sp = static_cast<std::uint16_t>(data[R_SPL] | (data[R_SPH] << 8));
            if (__builtin_expect(pc - 1 >= code_end_minus_one || pc == bad_interrupt_pc || sp < stack_floor, 0)) {
                const std::uint32_t fast_pc_before = avr->pc;
                avr->pc = pc;
                check_after_step(cpu_Running, fast_pc_before);
                if constexpr (kCover) edges->hit(pc);
                if (stop_requested_) break;
                continue;
            }
            avr->pc = pc;
            if constexpr (kCover) edges->hit(pc);
            // A stop requested during the instruction made stop_timer due:
            // the next turn leaves through finish() above.
        }
        const std::uint32_t steps = countdown_before - countdown;
        skip_countdown_ = countdown;
        steps_ += steps;  // one per turn of the loop above, each one countdown
        if (__builtin_expect(stop_requested_, 0)) break;
    }
    in_run_ = false;
    if (halted_ && debug_ != nullptr) debug_->halted(*this);
    if (halted_) return StopReason::Halted;
    if (stop_requested_) {
        stop_requested_ = false;
        avr_cycle_timer_cancel(avr, &stop_timer, this);
        if (real_stop_) {
            real_stop_ = false;
            return StopReason::Requested;
        }
    }
    return StopReason::ReachedTarget;
}


bool Mcu::check_after_step(int state, std::uint32_t pc_before) {
    char detail[160];
    if (state == cpu_Crashed) {
        add_finding(kSimavrCrash, avr_->pc,
                    last_error_log_.empty() ? "simavr stopped the core" : last_error_log_, true);
        return false;
    }
    if (state == cpu_Done && sleep_was_a_nop(avr_)) {
        // simavr ends the run at a SLEEP with interrupts off before looking at
        // SE; with SE = 0 the datasheet's SLEEP is a NOP (fixes/InterruptTiming).
        avr_->state = cpu_Running;
        return true;
    }
    if (state == cpu_Done || state == cpu_Stopped) {
        halted_ = true;
        stop_requested_ = true;
        halt_reason_ = state == cpu_Done ? "SLEEP with interrupts disabled: nothing can wake the core"
                                         : "simavr stopped the core";
        return false;
    }
    if (halted_) return false;  // a finding raised from inside the step (invalid opcode)
    const std::uint32_t pc = avr_->pc;
    // A reset puts the PC at the reset vector (0, or the boot section's start
    // with BOOTRST), which the oracles' range check always sends here.
    if (reset_seen_ || pc == 0) {
        const bool reset = reset_seen_;
        reset_seen_ = false;
        if (!reset && in_boot_section(pc_before)) {
            application_started();  // the boot loader jumps to the application
            return true;
        }
        const bool asked_for = watchdog_reset_seen_ && watchdog_watch_->requested(pc_before);
        after_reset();
        if (watchdog_reset_seen_) {
            watchdog_reset_seen_ = false;
            // A boot loader leaving through a watchdog reset (optiboot does) is not a finding.
            if (asked_for || options_.watchdog_resets_expected) {
                requested_resets_.push_back({avr_->cycle, pc_before, !asked_for});
            } else if (!in_boot_section(pc_before)) {
                add_finding(kWatchdogReset, pc_before,
                            "watchdog timed out; the MCU was reset (not asked for: the firmware served it with WDR "
                            "since it last set it up, or was not spinning in place)",
                            false);
            }
        } else {
            std::snprintf(detail, sizeof detail, "execution jumped to the reset vector from %s", describe_pc(pc_before).c_str());
            add_finding(kJumpToReset, pc_before, detail, false);
        }
        return true;
    }
    if (in_boot_section(pc)) return true;  // the boot loader's code
    if (pc == bad_interrupt_pc_) {
        const unsigned vector_bytes = avr_->vector_size != 0 ? avr_->vector_size : 4;
        std::snprintf(detail, sizeof detail,
                      "interrupt vector %u (at 0x%04x) has no handler; avr-libc would reset the MCU",
                      pc_before / vector_bytes, pc_before);
        add_finding(kBadInterrupt, pc, detail, true);
        return false;
    }
    if (pc >= code_end_bytes_) {
        std::snprintf(detail, sizeof detail, "PC 0x%04x is past the end of the program (0x%04x), came from %s",
                      pc, code_end_bytes_, describe_pc(pc_before).c_str());
        add_finding(kPcOutsideProgram, pc, detail, true);
        return false;
    }
    const unsigned sp = avr_->data[R_SPL] | (avr_->data[R_SPH] << 8);
    if (sp < stack_floor_ && !sp_half_written(avr_, pc_before)) {
        std::snprintf(detail, sizeof detail, "SP 0x%04x is below the end of .data/.bss (0x%04x): the stack overwrote static data",
                      sp, elf_.ram_end_of_static_data());
        add_finding(kStackOverflow, pc_before, detail, true);
        return false;
    }
    return true;
}

bool Mcu::sp_half_written_by(std::uint32_t pc_before) const { return sp_half_written(avr_, pc_before); }

}  // namespace avrbench
