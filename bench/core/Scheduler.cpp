#include "core/Scheduler.hpp"

#include <algorithm>

extern "C" {
#include <sim_avr.h>
#include <sim_cycle_timers.h>
}

namespace avrbench {

Scheduler::~Scheduler() {
    if (armed_) avr_cycle_timer_cancel(avr_, &Scheduler::on_timer, this);
}

void Scheduler::at(Cycle cycle, Callback fn) {
    std::uint32_t slot;
    if (free_slots_.empty()) {
        slot = static_cast<std::uint32_t>(slots_.size());
        slots_.push_back(std::move(fn));
    } else {
        slot = free_slots_.back();
        free_slots_.pop_back();
        slots_[slot] = std::move(fn);
    }
    queue_.push_back(Event{cycle, next_sequence_++, slot});
    std::push_heap(queue_.begin(), queue_.end(), Later{});
    // While dispatching, on_timer's return value re-arms for the new head.
    if (!dispatching_ && (!armed_ || cycle < armed_for_)) arm();
}

void Scheduler::after(Cycle delay_cycles, Callback fn) { at(avr_->cycle + delay_cycles, std::move(fn)); }

void Scheduler::arm() {
    if (queue_.empty()) return;
    const Cycle when = queue_.front().cycle;
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
    while (!self->queue_.empty() && self->queue_.front().cycle <= avr->cycle) {
        const Event event = self->queue_.front();
        std::pop_heap(self->queue_.begin(), self->queue_.end(), Later{});
        self->queue_.pop_back();
        // Called where it lies (the callback may schedule more: a deque
        // keeps it in place), then its slot is free again.
        Callback& fn = self->slots_[event.slot];
        fn(event.cycle);
        fn = nullptr;
        self->free_slots_.push_back(event.slot);
    }
    self->dispatching_ = false;
    if (self->queue_.empty()) return 0;
    self->armed_ = true;
    self->armed_for_ = self->queue_.front().cycle;
    // simavr re-inserts this timer at the returned absolute cycle; it must be
    // later than the current one or simavr drops it (sim_cycle_timers.c).
    return self->armed_for_ > avr->cycle ? self->armed_for_ : avr->cycle + 1;
}

}  // namespace avrbench
