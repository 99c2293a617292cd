// Presents an earlier cycle to whoever listens while it lives.
//
// Peripheral events (a timer's compare match, a USART bit edge) happen on
// their own clock's cycle, but simavr runs cycle timers and IRQ listeners at
// the end of the instruction in progress, up to 4 cycles later. Listeners
// stamp what they hear with avr->cycle (the trace recorder, a net terminal),
// so the event's owner sets it back to the event's cycle for the call and
// restores it after. Never moves the counter forward.
#pragma once

extern "C" {
#include <sim_avr.h>
}

#include "core/Time.hpp"

namespace avrbench {

class CycleAt {
public:
    CycleAt(avr_t* avr, Cycle at) : avr_(avr), saved_(avr->cycle) {
        if (at < saved_) avr->cycle = at;
    }
    ~CycleAt() { avr_->cycle = saved_; }
    CycleAt(const CycleAt&) = delete;
    CycleAt& operator=(const CycleAt&) = delete;

private:
    avr_t* avr_;
    Cycle saved_;
};

}  // namespace avrbench
