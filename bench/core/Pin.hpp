// One MCU pin (`PB5`) as a signal: watch its level, drive it from outside.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;

namespace avrbench {

class Pin {
public:
    using Listener = std::function<void(Cycle cycle, bool level)>;

    Pin(avr_t* avr, std::string name, avr_irq_t* irq);
    Pin(const Pin&) = delete;
    Pin& operator=(const Pin&) = delete;
    ~Pin();

    const std::string& name() const { return name_; }
    // The level simavr last saw on the pin: the PORT bit when it is an
    // output, the external drive or pull-up when it is an input.
    bool level() const;
    // Drives the pin from outside (a switch, another MCU); sets the PIN bit
    // and raises pin-change interrupts as the hardware would.
    void drive(bool level);
    void on_change(Listener fn);

    // The simavr IRQ of the pin, for hot-path observers (the trace recorder)
    // that register a plain C callback instead of a std::function.
    avr_irq_t* irq() const { return irq_; }
    avr_t* avr() const { return avr_; }

private:
    static void notify(avr_irq_t* irq, std::uint32_t value, void* param);

    avr_t* avr_;
    std::string name_;
    avr_irq_t* irq_;
    std::vector<Listener> listeners_;
    bool notify_registered_ = false;
    bool notified_level_ = false;
};

}  // namespace avrbench
