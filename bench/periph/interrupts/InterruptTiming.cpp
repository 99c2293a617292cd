// Interrupt response, RETI/SEI and SLEEP timing (ATmega328P §7.7, §7.7.1,
// §10.1; ATmega2560 §7.8, §7.8.1, §11.1; ATmega32 "Reset and Interrupt
// Handling", "Sleep Modes").
//
// simavr 1.6 departs from the datasheet in five ways, all corrected here
// through IRQ hooks, one I/O hook and the sleep callback (nothing on the
// per-instruction path):
//  1. entering an interrupt costs 0 cycles (the datasheet: 4 with a 2-byte PC,
//     5 with a 3-byte PC, before the vector's JMP);
//  2. after RETI, SEI and OUT SREG two instructions run before a pending
//     interrupt is served (the datasheet: one). simavr arms interrupt_state = -2;
//     RETI is seen through the vector's "running" IRQ, OUT SREG through an I/O
//     hook on SREG, SEI through a one-cycle cycle timer that runs only while an
//     interrupt is pending with I = 0, and an interrupt raised in the very
//     step that executed SEI through the "pending" IRQ; and, for an
//     interrupt raised during the instruction after SEI with nothing pending
//     at SEI (no hook sees that SEI), mcu/SimavrStep turns -2 into -1 at the
//     end of the step that set I, before simavr's service routine;
//  3. a sleep jump lands one cycle after the event that ends it;
//  4. a wake-up costs nothing (the datasheet: 4/5 cycles more plus the
//     start-up time of the sleep mode); SLEEP with a pending interrupt is a
//     NOP in simavr, the part sleeps and wakes at once;
//  5. SLEEP sleeps with SE = 0 (the datasheet: SE must be one, §10.1).
// It also replaces the sleep callback of install_virtual_sleep (virtual time:
// still no wall-clock wait).

extern "C" {
#include <sim_cycle_timers.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

constexpr unsigned kSleepOpcode = 0x9588;

class InterruptTiming final : public Fix {
public:
    explicit InterruptTiming(avr_t* avr) : avr_(avr), facts_(part_facts(avr)) {
        for (int i = 0; i < avr->interrupts.vector_count; ++i) {
            avr_irq_register_notify(avr->interrupts.vector[i]->irq + AVR_INT_IRQ_RUNNING, &on_running, this);
        }
        avr_irq_register_notify(avr->interrupts.irq + AVR_INT_IRQ_PENDING, &on_pending, this);
        sreg_hook_ = std::make_unique<IoWriteHook>(avr, R_SREG, &on_sreg_write, this);
        FixState<InterruptTiming>::add(avr, this);
        avr->sleep = &on_sleep;
    }

    ~InterruptTiming() override {
        for (int i = 0; i < avr_->interrupts.vector_count; ++i) {
            avr_irq_unregister_notify(avr_->interrupts.vector[i]->irq + AVR_INT_IRQ_RUNNING, &on_running, this);
        }
        avr_irq_unregister_notify(avr_->interrupts.irq + AVR_INT_IRQ_PENDING, &on_pending, this);
        avr_cycle_timer_cancel(avr_, &sei_watch, this);
        FixState<InterruptTiming>::remove(avr_);
    }

private:
    // Vector entry (value 1) and RETI (value 0).
    static void on_running(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<InterruptTiming*>(param);
        avr_t* avr = self->avr_;
        if (value == 0) {
            // RETI: "the AVR ... will always return to the main program and
            // execute one more instruction before any pending interrupt is served."
            if (avr->interrupt_state == -2) avr->interrupt_state = -1;
            return;
        }
        avr_cycle_count_t extra = static_cast<avr_cycle_count_t>(self->facts_.response_cycles);
        std::uint8_t mode = 0;
        bool woke = self->asleep_;
        if (woke) {
            mode = self->asleep_mode_;
        } else if (self->returns_behind_effective_sleep()) {
            // SLEEP executed with an interrupt already pending: the part
            // enters the sleep mode and wakes at once.
            woke = true;
            mode = sleep_mode(avr, self->facts_);
        }
        self->asleep_ = false;
        if (woke) {
            extra += static_cast<avr_cycle_count_t>(self->facts_.response_cycles) + wakeup_startup_cycles(avr, mode);
        }
        avr->cycle += extra;
    }

    // The PC just pushed is the instruction after a SLEEP that SE made effective.
    bool returns_behind_effective_sleep() const {
        if (facts_.sleep_register == 0 || (avr_->data[facts_.sleep_register] & facts_.se_mask) == 0) return false;
        const unsigned sp = avr_->data[R_SPL] | (avr_->data[R_SPH] << 8);
        std::uint32_t word = 0;
        for (int i = 1; i <= avr_->address_size; ++i) word = (word << 8) | avr_->data[(sp + i) & 0xFFFF];
        const std::uint32_t ret = word * 2;
        if (ret < 2 || ret > avr_->flashend) return false;
        return opcode_at(avr_, ret - 2) == kSleepOpcode;
    }

    // avr_raise_interrupt() raised something: while I = 0, watch for SEI.
    static void on_pending(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<InterruptTiming*>(param);
        avr_t* avr = self->avr_;
        if (value == 0) return;
        if (avr->sreg[S_I]) {
            // Raised in the step that executed SEI (simavr's -2 lasts only that
            // step): served after the one instruction that follows SEI, like an
            // interrupt already pending when SEI ran. Left at -2, simavr would
            // serve it one instruction later, after the CLI of `sei; nop; cli`,
            // and then never again: a vector already pending is not raised anew.
            if (avr->interrupt_state == -2) avr->interrupt_state = -1;
            return;
        }
        if (avr_cycle_timer_status(avr, &sei_watch, self) == 0) avr_cycle_timer_register(avr, 1, &sei_watch, self);
    }

    static avr_cycle_count_t sei_watch(avr_t* avr, avr_cycle_count_t, void*) {
        if (avr->sreg[S_I]) {
            // SEI just ran (timers run after the instruction, before the
            // interrupt service): "the instruction following SEI will be
            // executed before any pending interrupts".
            if (avr->interrupt_state == -2) avr->interrupt_state = -1;
            return 0;
        }
        if (!avr_has_pending_interrupts(avr)) return 0;
        return avr->cycle + 1;
    }

    static void on_sreg_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);  // simavr already split the value into avr->sreg
        if (avr->interrupt_state == -2) avr->interrupt_state = -1;
    }

    // Called by simavr's run loop on every step while the core sleeps, just
    // before it adds 1 + how_long to the cycle counter.
    static void on_sleep(avr_t* avr, avr_cycle_count_t how_long) {
        InterruptTiming* self = FixState<InterruptTiming>::find(avr);
        if (self == nullptr) return;
        const PartFacts& f = self->facts_;
        if (f.sleep_register != 0 && (avr->data[f.sleep_register] & f.se_mask) == 0) {
            // §10.1: SLEEP enters a sleep mode only when SE is one; otherwise it is a NOP.
            avr->state = cpu_Running;
            avr->cycle -= 1 + how_long;
            return;
        }
        // simavr lands one cycle past the next timer; land on it.
        avr_cycle_count_t land = avr->cycle + how_long;
        if (!self->asleep_) {
            self->asleep_ = true;
            self->asleep_mode_ = sleep_mode(avr, f);
            // A listener may start something now (the ADC in ADC Noise
            // Reduction mode): do not jump past it.
            const avr_cycle_count_t armed = notify_sleep_entry(avr, self->asleep_mode_);
            if (armed != 0 && armed > avr->cycle && armed < land) land = armed;
        }
        avr->cycle = land - 1 - how_long;
    }

    avr_t* avr_;
    PartFacts facts_;
    std::unique_ptr<IoWriteHook> sreg_hook_;
    bool asleep_ = false;
    std::uint8_t asleep_mode_ = 0;
};

}  // namespace

std::unique_ptr<Fix> install_interrupt_timing(avr_t* avr) { return std::make_unique<InterruptTiming>(avr); }

}  // namespace avrbench
