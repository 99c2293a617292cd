// Who listens on a simavr IRQ. simavr keeps an IRQ's listeners in a list of
// `avr_irq_hook_t` that sim_irq.h declares only by name; its layout below is
// Debian's simavr 1.6 (1.6+dfsg-3, simavr/sim/sim_irq.c), the one place in the
// bench that reads it. Re-check it when the simavr version changes
// (PeriodicOutputs.* fails if the layout is wrong: no wave would begin).
#pragma once

#include <cstddef>

extern "C" {
#include <sim_irq.h>
}

namespace avrbench {

namespace simavr16 {
struct IrqHook {
    IrqHook* next;
    int busy;
    avr_irq_t* chain;
    avr_irq_notify_t notify;
    void* param;
};
}  // namespace simavr16

inline bool irq_has_listeners(const avr_irq_t* irq) { return irq->hook != nullptr; }

// Every listener of `irq` is a notify callback whose parameter is one of
// `allowed` (no chained IRQ).
inline bool irq_listeners_within(const avr_irq_t* irq, const void* const* allowed, std::size_t count) {
    for (auto* h = reinterpret_cast<const simavr16::IrqHook*>(irq->hook); h != nullptr; h = h->next) {
        if (h->chain != nullptr || h->notify == nullptr) return false;
        bool known = false;
        for (std::size_t i = 0; i < count; ++i) known = known || (allowed[i] != nullptr && h->param == allowed[i]);
        if (!known) return false;
    }
    return true;
}

}  // namespace avrbench
