#include "core/Scheduler.hpp"

extern "C" {
#include <sim_avr.h>
#include <sim_cycle_timers.h>
}

namespace avrbench {

Scheduler::~Scheduler() {
    if (armed_) avr_cycle_timer_cancel(avr_, &Scheduler::on_timer, this);
}

void Scheduler::at(Cycle cycle, Callback fn) {
    queue_.push(Event{cycle, next_sequence_++, std::move(fn)});
    // While dispatching, on_timer's return value re-arms for the new head.
    if (!dispatching_ && (!armed_ || cycle < armed_for_)) arm();
}

void Scheduler::after(Cycle delay_cycles, Callback fn) { at(avr_->cycle + delay_cycles, std::move(fn)); }

void Scheduler::arm() {
    if (queue_.empty()) return;
    const Cycle when = queue_.top().cycle;
    const Cycle delay = when > avr_->cycle ? when - avr_->cycle : 0;
    avr_cycle_timer_register(avr_, delay, &Scheduler::on_timer, this);
    armed_ = true;
    armed_for_ = when;
}

void Scheduler::rearm() {
    armed_ = false;
    arm();
}

std::uint64_t Scheduler::on_timer(avr_t* avr, std::uint64_t /*when*/, void* param) {
    auto* self = static_cast<Scheduler*>(param);
    self->dispatching_ = true;
    self->armed_ = false;
    while (!self->queue_.empty() && self->queue_.top().cycle <= avr->cycle) {
        // Move the event out before popping: the callback may schedule more.
        Event event = std::move(const_cast<Event&>(self->queue_.top()));
        self->queue_.pop();
        event.fn(event.cycle);
    }
    self->dispatching_ = false;
    if (self->queue_.empty()) return 0;
    self->armed_ = true;
    self->armed_for_ = self->queue_.top().cycle;
    // simavr re-inserts this timer at the returned absolute cycle; it must be
    // later than the current one or simavr drops it (sim_cycle_timers.c).
    return self->armed_for_ > avr->cycle ? self->armed_for_ : avr->cycle + 1;
}

}  // namespace avrbench
