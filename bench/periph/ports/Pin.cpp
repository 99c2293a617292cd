#include "periph/ports/Pin.hpp"

#include "periph/timer/CompareOutputPins.hpp"
#include "periph/interrupts/Interrupts.hpp"

extern "C" {
#include <avr_ioport.h>
#include <sim_avr.h>
#include <sim_irq.h>
}

namespace avrbench {

Pin::Pin(avr_t* avr, std::string name, avr_irq_t* irq, avr_ioport_t* port, int bit)
    : avr_(avr), name_(std::move(name)), irq_(irq), port_(port), mask_(static_cast<std::uint8_t>(1u << bit)), bit_(bit),
      overrides_(CompareOutputPins::of(avr)) {
    const PartFacts facts = part_facts(avr);
    pud_register_ = facts.pud_register;
    pud_mask_ = facts.pud_mask;
}

Pin::~Pin() {
    if (notify_registered_) avr_irq_unregister_notify(irq_, &Pin::notify, this);
}

bool Pin::level() const { return (irq_->value & 0xff) != 0; }

void Pin::drive(bool level) {
    port_->external.pull_mask = static_cast<std::uint8_t>(port_->external.pull_mask | mask_);
    port_->external.pull_value = static_cast<std::uint8_t>(level ? (port_->external.pull_value | mask_)
                                                                  : (port_->external.pull_value & ~mask_));
    avr_raise_irq(irq_, level ? 1 : 0);
}

void Pin::release() {
    port_->external.pull_mask = static_cast<std::uint8_t>(port_->external.pull_mask & ~mask_);
    port_->external.pull_value = static_cast<std::uint8_t>(port_->external.pull_value & ~mask_);
    if (!is_output()) avr_raise_irq(irq_, internal_pull_up() ? 1 : 0);
}

bool Pin::driven() const { return (port_->external.pull_mask & mask_) != 0; }

bool Pin::internal_pull_up() const {
    const bool pull_ups_disabled = pud_register_ != 0 && (avr_->data[pud_register_] & pud_mask_) != 0;
    return !is_output() && (avr_->data[port_->r_port] & mask_) != 0 && !pull_ups_disabled;
}

bool Pin::is_output() const {
    return (avr_->data[port_->r_ddr] & mask_) != 0 || (overrides_ != nullptr && overrides_->forces_output(port_, bit_));
}

void Pin::on_change(Listener fn) {
    // A wave on this pin (periph/timer/PeriodicOutput.hpp) was accepted for the
    // listeners it had: end it, so the new one hears every edge.
    if (CompareOutputPins* outputs = CompareOutputPins::of(avr_)) outputs->stop_all_waves();
    listeners_.push_back(std::move(fn));
    if (!notify_registered_) {
        notified_level_ = level();
        avr_irq_register_notify(irq_, &Pin::notify, this);
        notify_registered_ = true;
    }
}

// simavr raises a port's pin IRQs on every PORT write, changed or not, so an
// edge is a change from the level the listeners last heard. (The low byte is
// the level: simavr ors AVR_IOPORT_OUTPUT = 0x100 into some raises.)
void Pin::notify(avr_irq_t*, std::uint32_t value, void* param) {
    auto* self = static_cast<Pin*>(param);
    const bool level = (value & 0xff) != 0;
    if (level == self->notified_level_) return;
    self->notified_level_ = level;
    for (auto& fn : self->listeners_) fn(self->avr_->cycle, level);
}

}  // namespace avrbench
