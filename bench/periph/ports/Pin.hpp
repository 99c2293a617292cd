// One MCU pin (`PB5`) as a signal: watch its level, drive it from outside.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;
struct avr_ioport_t;

namespace avrbench {

class CompareOutputPins;

class Pin {
public:
    using Listener = std::function<void(Cycle cycle, bool level)>;

    Pin(avr_t* avr, std::string name, avr_irq_t* irq, avr_ioport_t* port, int bit);
    Pin(const Pin&) = delete;
    Pin& operator=(const Pin&) = delete;
    ~Pin();

    const std::string& name() const { return name_; }
    // The level simavr last saw on the pin: the PORT bit when it is an
    // output, the external drive or pull-up when it is an input.
    bool level() const;
    // Drives the pin from outside (a switch, another MCU); sets the PIN bit
    // and raises pin-change interrupts as the hardware would. The level is
    // held as simavr's "external" state of the pin, so later PORT writes (which
    // make simavr re-raise every input's pull-up level) do not override it.
    void drive(bool level);
    // Stops driving: the pin reads its internal pull-up (PORTxn = 1 while an
    // input) or, floating, 0.
    void release();
    bool driven() const;
    // The firmware has the pin as an input with PORTxn = 1 and pull-ups
    // enabled (PUD = 0).
    bool internal_pull_up() const;
    // The pin drives its level: the firmware has it as an output (DDxn = 1),
    // or a peripheral forces it out (TxDn while TXEN is set).
    bool is_output() const;
    void on_change(Listener fn);
    std::size_t listener_count() const { return listeners_.size(); }

    // The simavr IRQ of the pin, for hot-path observers (the trace recorder)
    // that register a plain C callback instead of a std::function.
    avr_irq_t* irq() const { return irq_; }
    avr_t* avr() const { return avr_; }
    avr_ioport_t* port() const { return port_; }
    std::uint8_t mask() const { return mask_; }  // the pin's bit in its port's registers

private:
    static void notify(avr_irq_t* irq, std::uint32_t value, void* param);

    avr_t* avr_;
    std::string name_;
    avr_irq_t* irq_;
    avr_ioport_t* port_;
    std::uint8_t mask_;
    int bit_;
    const CompareOutputPins* overrides_ = nullptr;  // who may force the pin out
    unsigned short pud_register_ = 0;  // 0: the part has no PUD bit the bench knows
    std::uint8_t pud_mask_ = 0;
    std::vector<Listener> listeners_;
    bool notify_registered_ = false;
    bool notified_level_ = false;
};

}  // namespace avrbench
