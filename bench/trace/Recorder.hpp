// Connects MCU signals to a Timeline: pins (every edge with its cycle) and
// UART transmit bytes. Pin edges arrive through a plain simavr IRQ callback
// that appends to the timeline, the cheapest hook simavr offers.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mcu/Mcu.hpp"
#include "parts/Part.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {

class Recorder {
public:
    explicit Recorder(Timeline& timeline);
    ~Recorder();
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;

    // Adds "<mcu name>.<pin name>" as a wire, starting with its current level.
    SignalId trace_pin(Mcu& mcu, Pin& pin);
    // Adds "<mcu name>.uart<n>_tx" as an 8-bit bus: one event per byte, at the
    // cycle of its start bit.
    SignalId trace_uart_tx(Mcu& mcu, Uart& uart);
    // Adds "<mcu name>.uart<n>_rx": one event per byte the receiver takes, at
    // the cycle its receive-complete flag is set.
    SignalId trace_uart_rx(Mcu& mcu, Uart& uart);
    // Every address and data byte the MCU puts on its I2C bus as master, as
    // an 8-bit bus signal "twi" (one event per byte, at the end of its ACK bit).
    SignalId trace_twi(Mcu& mcu, Twi& twi);

    // Every signal the part publishes (positions, levels, temperatures), in a
    // scope named after the part, stamped with the part's clock.
    std::vector<SignalId> trace_part(Part& part);
    // Only the part's signals named in `only` (BadInput naming the part's
    // signals for one it does not have).
    std::vector<SignalId> trace_part(Part& part, const std::vector<std::string>& only);

    // Pins named in `spec`: "PB5,PD2", "PORTB" (its 8 pins) or "all" (every
    // pin of every port the MCU has). Throws BadInput on an unknown name.
    std::vector<SignalId> trace_pins(Mcu& mcu, const std::string& spec);

private:
    struct PinSink;
    Timeline& timeline_;
    std::vector<std::unique_ptr<PinSink>> pin_sinks_;
};

}  // namespace avrbench
