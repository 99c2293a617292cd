// Watchdog interrupt mode (ATmega328P §11.8 "Watchdog Timer" Table 11-1 and
// WDTCSR §11.9.2; ATmega2560 §12.4, §12.5.2).
//
//  - In Interrupt Mode (WDE = 0, WDIE = 1) the watchdog interrupts at every
//    time-out; WDIE is cleared by hardware only in Interrupt and System Reset
//    Mode (WDE = 1). simavr 1.6 clears WDIE whenever the interrupt is taken,
//    so a firmware using the watchdog as a periodic wake-up gets one interrupt
//    and then none.
//  - WDIF "is cleared by writing a logic one to the flag"; simavr keeps it.
//  - A change of WDP in the timed sequence applies to the running watchdog
//    (§11.9.2); simavr 1.6 compares the new WDP with itself (it reads the
//    "old" value after storing the new) and keeps the old period until the
//    watchdog is next enabled: the time-out is restarted here with the new
//    one, counted from when the counter last started (WDR or enable).
// The ATmega32's watchdog (simavr's "128" declaration, no WDIE) is left alone.
#include <algorithm>

extern "C" {
#include <avr_watchdog.h>
#include <sim_cycle_timers.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class Watchdog final : public Fix {
public:
    Watchdog(avr_t* avr, avr_watchdog_t* wdt) : avr_(avr), wdt_(wdt) {
        // Registered after simavr's own notify, so it runs first (simavr
        // prepends hooks).
        avr_irq_register_notify(wdt->watchdog.irq + AVR_INT_IRQ_PENDING, &on_pending, this);
        hook_ = std::make_unique<IoWriteHook>(avr, static_cast<avr_io_addr_t>(wdt->wde.reg), &on_write, this);
    }
    ~Watchdog() override {
        hook_.reset();
        avr_irq_unregister_notify(wdt_->watchdog.irq + AVR_INT_IRQ_PENDING, &on_pending, this);
    }

private:
    static void on_pending(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<Watchdog*>(param);
        avr_t* avr = self->avr_;
        // The interrupt is being taken (simavr clears WDIF right after this).
        // simavr's notify clears WDIE when it still sees WDIF set: in
        // Interrupt Mode clear WDIF first so that WDIE stays.
        if (value == 0 && !avr_regbit_get(avr, self->wdt_->wde)) avr_regbit_clear(avr, self->wdt_->watchdog.raised);
    }

    // simavr's watchdog time-out: of the pending cycle timers whose parameter
    // is the module, the latest (the other clears WDCE four cycles on).
    avr_cycle_timer_slot_p pending_timer() const {
        avr_cycle_timer_slot_p latest = nullptr;
        for (auto* t = avr_->cycle_timers.timer; t != nullptr; t = t->next) {
            if (t->param == wdt_ && (latest == nullptr || t->when > latest->when)) latest = t;
        }
        return latest;
    }

    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<Watchdog*>(hook.context());
        const avr_regbit_t wdif = self->wdt_->watchdog.raised;
        const avr_cycle_count_t period_before = self->wdt_->cycle_count;
        const auto* before = self->pending_timer();
        const avr_cycle_count_t when_before = before != nullptr ? before->when : 0;
        hook.write_original(avr, addr, value);
        auto* after = self->pending_timer();
        if (after != nullptr && before != nullptr && after->when == when_before && self->wdt_->cycle_count != period_before) {
            // The same time-out, a new period: the counter started at
            // when - old period and now ends at its start + the new period
            // (at once if it is already past it: the datasheet's warning).
            const avr_cycle_count_t started = when_before - std::min(when_before, period_before);
            const avr_cycle_count_t due = std::max<avr_cycle_count_t>(started + self->wdt_->cycle_count, avr->cycle + 1);
            avr_cycle_timer_register(avr, due - avr->cycle, after->timer, self->wdt_);
        }
        if (wdif.reg == addr && (value & (wdif.mask << wdif.bit)) != 0) {
            if (self->wdt_->watchdog.pending) unpend_interrupt(avr, &self->wdt_->watchdog);
            avr_regbit_clear(avr, wdif);
        }
        sync_enables(avr, addr);
    }

    avr_t* avr_;
    avr_watchdog_t* wdt_;
    std::unique_ptr<IoWriteHook> hook_;
};

// The older megas' watchdog (ATmega32 "Watchdog Timer", Table 17; the same
// on the ATmega8/16/64/128): "clocked from a separate On-chip Oscillator which
// runs at 1 MHz", WDP2:0 = 000 is 16K cycles (16.3 ms typical at 5 V); and
// WDTCR resets to 0, so a watchdog reset leaves the watchdog off. simavr uses
// the newer parts' 2K cycles of 128 kHz (16 ms) and re-enables the watchdog at
// its shortest period after a watchdog reset (the newer parts' WDRF rule), so
// such a firmware resets again every 16 ms.
class OldMegaWatchdog final : public Fix {
public:
    OldMegaWatchdog(avr_t* avr, avr_watchdog_t* wdt) : avr_(avr), wdt_(wdt) {
        hook_ = std::make_unique<IoWriteHook>(avr, static_cast<avr_io_addr_t>(wdt->wde.reg), &on_write, this);
        original_reset_ = wdt->io.reset;
        wdt->io.reset = &on_reset;
        FixState<OldMegaWatchdog>::add(&wdt->io, this);
        correct_period();
    }
    ~OldMegaWatchdog() override {
        hook_.reset();
        wdt_->io.reset = original_reset_;
        FixState<OldMegaWatchdog>::remove(&wdt_->io);
    }

private:
    // simavr's watchdog timer: the pending cycle timer whose parameter is the module.
    avr_cycle_timer_slot_p pending_timer() const {
        for (auto* t = avr_->cycle_timers.timer; t != nullptr; t = t->next) {
            if (t->param == wdt_) return t;
        }
        return nullptr;
    }

    void correct_period() {
        const unsigned wdp = avr_regbit_get_array(avr_, wdt_->wdp, 3);
        wdt_->cycle_count = (avr_cycle_count_t{16384} << wdp) * avr_->frequency / 1000000u;
    }

    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<OldMegaWatchdog*>(hook.context());
        const auto* before = self->pending_timer();
        const avr_cycle_count_t when_before = before != nullptr ? before->when : 0;
        hook.write_original(avr, addr, value);
        self->correct_period();
        auto* after = self->pending_timer();
        if (after != nullptr && (before == nullptr || after->when != when_before)) {
            // simavr (re)started the time-out in this write: with its period; restart with ours.
            const avr_cycle_timer_t fn = after->timer;
            avr_cycle_timer_register(avr, self->wdt_->cycle_count, fn, self->wdt_);
        }
    }

    static void on_reset(avr_io_t* io) {
        OldMegaWatchdog* self = FixState<OldMegaWatchdog>::find(io);
        self->original_reset_(io);
        // WDTCR's reset value is 0: the watchdog is off after any reset.
        if (auto* t = self->pending_timer()) avr_cycle_timer_cancel(self->avr_, t->timer, self->wdt_);
        avr_regbit_clear(self->avr_, self->wdt_->wde);
        self->correct_period();
    }

    avr_t* avr_;
    avr_watchdog_t* wdt_;
    std::unique_ptr<IoWriteHook> hook_;
    void (*original_reset_)(avr_io_t*) = nullptr;
};

}  // namespace

std::unique_ptr<Fix> install_watchdog(avr_t* avr) {
    avr_io_t* io = find_io_module(avr, "watchdog");
    if (io == nullptr) return nullptr;
    auto* wdt = reinterpret_cast<avr_watchdog_t*>(io);
    // Older megas (simavr's "128" declaration: no interrupt, vector 0).
    if (wdt->watchdog.vector == 0 || wdt->watchdog.raised.reg == 0) {
        if (part_facts(avr).old_mega) return std::make_unique<OldMegaWatchdog>(avr, wdt);
        return nullptr;
    }
    return std::make_unique<Watchdog>(avr, wdt);
}

}  // namespace avrbench
