// The pins a peripheral drives in place of PORTxn: the OCnx pins of the
// timers (TimerModel.cpp) and the USARTs' TxDn pins (UartTransmitter.cpp).
//
// TxDn (ATmega328P §20.6 and Table 14-9, DDOE = TXEN, DDOV = 1, PVOE = TXEN;
// ATmega2560 §22.6; ATmega32 "USART"): while the transmitter is enabled the
// USART drives the pin as an output whatever DDxn says - a "forced output"
// driver here. Whoever decides what a pin drives (periph/ports/Pin::is_output, the
// board's net terminals) asks forces_output() and hears when it changes.
//
// Datasheet (ATmega328P §15.6 / §16.8 "Compare Match Output Unit", ATmega2560
// §16.6 / §17.8): while the COMnx bits connect the
// output compare OCnx, the Waveform Generator drives the pin in place of
// PORTxn, and PORTxn keeps what the firmware last wrote (it is used again
// once COMnx is cleared); OCnx reaches the pin only while DDxn is one.
//
// simavr 1.6 instead connects each comparator IRQ straight to its pin with
// AVR_IOPORT_OUTPUT, which rewrites PORTxn on every compare match, and a PORTx
// write by the firmware re-raises the pin from PORTxn. Here the timer model
// drives the pin itself, and hooks on PORTx (write), PINx (read and write)
// and DDRx (write) of the ports that carry OCnx pins keep simavr's port
// module seeing the OCnx level on those pins while the firmware sees its own
// PORTxn value.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "periph/timer/PeriodicOutput.hpp"
#include "periph/Fix.hpp"

struct avr_irq_t;
struct avr_ioport_t;

namespace avrbench {

class CompareOutputPins {
public:
    explicit CompareOutputPins(avr_t* avr);
    ~CompareOutputPins();
    CompareOutputPins(const CompareOutputPins&) = delete;
    CompareOutputPins& operator=(const CompareOutputPins&) = delete;

    // Adds the pin a timer comparator drives (its `com_pin` regbit); returns
    // the driver's id, or -1 when the core has no such pin.
    int add(avr_regbit_t com_pin, avr_irq_t* compare_irq);
    // Adds pin `bit` of port `port_letter` as a forced output (a USART's
    // TxDn); the driver's id, or -1 when the core has no such port.
    int add_forced_output(char port_letter, int bit);
    // Whether a connected forced-output driver holds pin `bit` of `io`.
    bool forces_output(const avr_ioport_t* io, int bit) const;
    // Called whenever a forced output connects or disconnects (its pin's
    // direction changed without a DDRx write).
    // Returns an id for remove_direction_listener.
    int on_direction_change(std::function<void()> fn);
    void remove_direction_listener(int id);
    // The comparator's state: whether COMnx connects OCnx to the pin, and the
    // level of the OCnx register. Raises the pin when what it shows changes.
    void set(int id, bool connected, bool level);
    // After avr_reset(): simavr's timer reset has connected the comparator
    // IRQs straight to their pins again, and every COMnx is zero.
    void after_reset();

    // Periodic waves (periph/timer/PeriodicOutput.hpp). The instance on `avr`'s
    // timers, or nullptr when the bench does not model them.
    static CompareOutputPins* of(const avr_t* avr);
    // Who takes pin `bit` of `io` as a wave; nullptr removes the sink (for a
    // board's teardown: a running wave goes on without telling anyone).
    void set_sink(avr_ioport_t* io, int bit, PeriodicOutputSink* sink);
    // The timer that owns driver `id` ends its wave and catches the pin up to
    // `now` when the pin is about to be observed (its port written, PINx read).
    using StopWave = void (*)(void* timer, Cycle now);
    // Hands driver `id`'s pin out as `wave` if every condition in
    // PeriodicOutput.hpp holds and the sink takes it.
    bool begin_wave(int id, const PeriodicWave& wave, StopWave stop, void* timer);
    // The wave ended at period boundary `at` (the driver is at its start level).
    void end_wave(int id, Cycle at);
    // Has every timer end its waves now (Mcu::settle_periodic_outputs).
    void stop_all_waves();

private:
    struct Port;
    struct Driver {
        Port* port = nullptr;
        std::uint8_t bit = 0;
        avr_irq_t* compare_irq = nullptr;  // nullptr for a forced output
        avr_irq_t* pin_irq = nullptr;
        bool forces_output = false;
        bool connected = false;
        bool level = false;
        bool waving = false;
        StopWave stop = nullptr;
        void* timer = nullptr;
    };
    struct Sink {
        avr_ioport_t* io = nullptr;
        std::uint8_t bit = 0;
        PeriodicOutputSink* sink = nullptr;
    };

    PeriodicOutputSink* sink_for(const Driver& d) const;
    bool only_known_listeners(const Driver& d, const PeriodicOutputSink& sink) const;
    // Ends the waves on `port`'s pins before the firmware or the port module
    // looks at them.
    void stop_waves(Port& port);
    static void on_pcmsk_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    Port* port_for(avr_ioport_t* io);
    void update_pin(Port& port, std::uint8_t bit);
    // Whether a connected OCnx drives pin `bit` of `port`, and its level when
    // PORTx holds `port_value` (the 2560's modulator on PB7 reads PORTB7).
    void combine(Port& port, std::uint8_t bit, std::uint8_t port_value);

    static void on_port_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);
    static void on_pin_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);
    static void on_ddr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);
    static std::uint8_t on_pin_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t addr);

    avr_t* avr_;
    bool pin_write_toggles_;
    std::vector<std::unique_ptr<Port>> ports_;
    std::vector<Driver> drivers_;
    std::vector<Sink> sinks_;
    std::vector<std::pair<int, std::function<void()>>> direction_listeners_;
    int next_listener_id_ = 0;
    void tell_direction_listeners();
};

}  // namespace avrbench
