// I/O port corrections (ATmega328P §14.2.2 "Toggling the Pin", §8.5 "I/O
// Memory", §11.1 "Resetting the AVR"; ATmega2560 §13.2.2, §8.4, §12.1;
// ATmega32 "I/O Ports").
//
//  - SBI PINx,n: simavr executes SBI as a read-modify-write of PINx, so every
//    pin that reads high is toggled too; on the 328P/2560 SBI writes only bit n
//    ("writing a logic one to PINxn toggles the value of PORTxn"), and CBI
//    PINx,n writes nothing.
//  - The ATmega32's PIN registers are read-only: simavr toggles PORTx on a
//    PINx write as on the newer parts.
//  - A reset (watchdog) zeroes PORT and DDR, but simavr raises no pin IRQ, so a
//    pin that was an output driving high still looks high. "The I/O ports of
//    the AVR are immediately reset to their initial state when a reset source
//    goes active": inputs without pull-up, i.e. the level the outside world
//    drives, or low when nothing drives the pin (the bench's floating level).
#include <string_view>
#include <vector>

extern "C" {
#include <avr_ioport.h>
#include <sim_io.h>
}

#include "core/fixes/Fixes.hpp"
#include "core/fixes/Interrupts.hpp"

namespace avrbench {
namespace {

class PortPins;
Registry<avr_io_t, PortPins>& port_registry() {
    static Registry<avr_io_t, PortPins> r;
    return r;
}

class PortPins final : public Fix {
public:
    explicit PortPins(avr_t* avr) : facts_(part_facts(avr)) {
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "port") continue;
            auto* port = reinterpret_cast<avr_ioport_t*>(io);
            ports_.push_back({port, io->reset});
            io->reset = &on_reset;
            port_registry().add(io, this);
            pin_hooks_.push_back(std::make_unique<IoWriteHook>(avr, port->r_pin, &on_pin_write, this));
        }
    }

    ~PortPins() override {
        pin_hooks_.clear();
        for (auto& p : ports_) {
            p.port->io.reset = p.original_reset;
            port_registry().remove(&p.port->io);
        }
    }

private:
    struct Port {
        avr_ioport_t* port;
        void (*original_reset)(avr_io_t*);
    };

    static void on_pin_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<PortPins*>(hook.context());
        if (!self->facts_.pin_write_toggles) return;  // read-only PIN register
        const std::uint8_t toggles = self->facts_.sbi_single_bit ? single_bit_write_value(avr, addr, value) : value;
        if (toggles == 0) return;
        hook.write_original(avr, addr, toggles);
    }

    static void on_reset(avr_io_t* io) {
        PortPins* self = port_registry().find(io);
        auto* port = reinterpret_cast<avr_ioport_t*>(io);
        for (auto& p : self->ports_) {
            if (p.port == port && p.original_reset != nullptr) p.original_reset(io);
        }
        // PORT and DDR are zero now: every pin is an input without pull-up.
        for (int bit = 0; bit < 8; ++bit) {
            const std::uint8_t mask = static_cast<std::uint8_t>(1u << bit);
            const bool driven = (port->external.pull_mask & mask) != 0;
            const bool level = driven && (port->external.pull_value & mask) != 0;
            avr_raise_irq(port->io.irq + bit, level ? 1 : 0);
        }
    }

    PartFacts facts_;
    std::vector<Port> ports_;
    std::vector<std::unique_ptr<IoWriteHook>> pin_hooks_;
};

}  // namespace

std::unique_ptr<Fix> install_port_pins(avr_t* avr) { return std::make_unique<PortPins>(avr); }

}  // namespace avrbench
