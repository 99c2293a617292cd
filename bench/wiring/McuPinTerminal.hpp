// An MCU pin on a net, and the watch that tells the net when the firmware
// changes what the pin drives.
//
// What an MCU pin drives (ATmega328P §14.2, Table 14-1; 2560 §13.2; m32
// "I/O Ports"): DDxn = 1, push-pull at the pin's output level (PORTxn, or the
// timer's compare output); DDxn = 0 with PORTxn = 1 and PUD = 0, the internal
// pull-up R_PU; otherwise nothing (tri-state). The watch hooks the port's PORT,
// DDR and PIN registers (and PUD, and resets) so a change of direction or
// pull-up re-resolves the net even when the pin's level stays the same, and
// hooks PIN reads to report firmware reading a floating net.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "mcu/Mcu.hpp"
#include "periph/ports/Pin.hpp"
#include "wiring/Net.hpp"

struct avr_ioport_t;

namespace avrbench {

class IoWriteHook;
class IoReadHook;

// R_PU, "I/O pin pull-up resistor": 20-50 kohm on the 328P (§28.2), 2560
// (§31.2) and m32 (§28); the bench takes the middle. It matters only in a
// divider with a board resistor, where either end of the range gives the same
// logic level for the usual 1-10 kohm resistors.
inline constexpr double kInternalPullUpOhm = 35e3;

// Also the pin's PeriodicOutputSink: a timer's repeating compare output is
// handed to the net's other terminals as a wave when every one of them is a
// part input that follows it (a heater's gate) on this MCU's clock and
// nothing else listens on the pin.
class McuPinTerminal final : public Terminal, public PeriodicOutputSink {
public:
    McuPinTerminal(Mcu& mcu, Pin& pin);
    ~McuPinTerminal() override;
    McuPinTerminal(const McuPinTerminal&) = delete;
    McuPinTerminal& operator=(const McuPinTerminal&) = delete;
    std::string label() const override { return mcu_.name() + "." + pin_.name(); }
    TerminalRole role() const override { return TerminalRole::Bidirectional; }
    Mcu* clock_mcu() const override { return &mcu_; }
    Pin* mcu_pin() const override { return &pin_; }
    Drive drive_state() const override;
    void receive(const Resolution& resolution) override;
    bool begin_wave(const PeriodicWave& wave) override;
    void end_wave(Cycle at) override;
    const void* listener_param() const override { return &pin_; }

    Mcu& mcu() const { return mcu_; }
    Pin& pin() const { return pin_; }
    // Offers this terminal to the MCU as the pin's PeriodicOutputSink (the
    // board does, once the net is complete).
    void register_as_sink();
    void unregister_as_sink();
    // The firmware may have changed the pin's direction or pull-up: the net
    // resolves again only if what the pin drives did change (every PORT write
    // of a step pulse comes here).
    void refresh();

private:
    Mcu& mcu_;
    Pin& pin_;
    bool level_;   // the pin's level as last raised
    Drive drive_;  // what the net last heard this pin drive
    bool registered_as_sink_ = false;
};

// One per MCU with pins on nets.
class McuPortWatch {
public:
    explicit McuPortWatch(Mcu& mcu);
    ~McuPortWatch();
    McuPortWatch(const McuPortWatch&) = delete;
    McuPortWatch& operator=(const McuPortWatch&) = delete;

    void add(McuPinTerminal& terminal);

private:
    struct PortWatch {
        McuPortWatch* owner = nullptr;
        avr_ioport_t* port = nullptr;
        std::vector<McuPinTerminal*> terminals;
    };
    static void on_write(IoWriteHook& hook, avr_t* avr, unsigned short addr, std::uint8_t value);
    static std::uint8_t on_pin_read(IoReadHook& hook, avr_t* avr, unsigned short addr);
    static void on_pud_write(IoWriteHook& hook, avr_t* avr, unsigned short addr, std::uint8_t value);
    void refresh_all();

    Mcu& mcu_;
    int direction_listener_ = -1;
    std::map<avr_ioport_t*, std::unique_ptr<PortWatch>> ports_;
    std::vector<std::unique_ptr<IoWriteHook>> write_hooks_;
    std::vector<std::unique_ptr<IoReadHook>> read_hooks_;
};

// Which bits of a PINx byte the instruction at byte address `pc` uses (an
// SBIS tests one; an IN masked at once by ANDI uses the mask; 0xFF: all).
std::uint8_t pin_bits_used(const avr_t* avr, std::uint32_t pc);

}  // namespace avrbench
