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
//  - Pull-ups switched off: simavr raises the pull-up level when an input's
//    PORTxn becomes 1 but lowers nothing when it becomes 0, when DDxn turns an
//    output driving high into an input without pull-up, or when PUD disables
//    every pull-up (§14.2.1, Table 14-1: that pin is tri-state). After every
//    PORTx, DDRx and PUD write, each input nothing drives is set to its
//    pull-up (1) or to the floating level (0).
#include <string_view>
#include <vector>

extern "C" {
#include <avr_ioport.h>
#include <sim_io.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class PortPins final : public Fix {
public:
    explicit PortPins(avr_t* avr) : facts_(part_facts(avr)) {
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "port") continue;
            auto* port = reinterpret_cast<avr_ioport_t*>(io);
            ports_.push_back({port, io->reset});
            io->reset = &on_reset;
            FixState<PortPins>::add(io, this);
            // A write to one port's PIN, PORT or DDR register can change only that port's inputs.
            hook_contexts_.push_back(std::make_unique<PortHook>(PortHook{this, port}));
            PortHook* ctx = hook_contexts_.back().get();
            pin_hooks_.push_back(std::make_unique<IoWriteHook>(avr, port->r_pin, &on_pin_write, ctx));
            pin_hooks_.push_back(std::make_unique<IoWriteHook>(avr, port->r_port, &on_port_or_ddr_write, ctx));
            pin_hooks_.push_back(std::make_unique<IoWriteHook>(avr, port->r_ddr, &on_port_or_ddr_write, ctx));
        }
        // PUD: MCUCR bit 4 on the 328P/2560 (§14.4.1 / §13.4.1), SFIOR bit 2 on the ATmega32.
        if (facts_.pud_register != 0) {
            pud_register_ = facts_.pud_register;
            pud_mask_ = facts_.pud_mask;
            pin_hooks_.push_back(std::make_unique<IoWriteHook>(avr, pud_register_, &on_pud_write, this));
        }
    }

    ~PortPins() override {
        pin_hooks_.clear();
        for (auto& p : ports_) {
            p.port->io.reset = p.original_reset;
            FixState<PortPins>::remove(&p.port->io);
        }
    }

private:
    struct Port {
        avr_ioport_t* port;
        void (*original_reset)(avr_io_t*);
    };

    struct PortHook {
        PortPins* self;
        avr_ioport_t* port;
    };

    static void on_pin_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* ctx = static_cast<PortHook*>(hook.context());
        if (!ctx->self->facts_.pin_write_toggles) return;  // read-only PIN register
        const std::uint8_t toggles = ctx->self->facts_.sbi_single_bit ? single_bit_write_value(avr, addr, value) : value;
        if (toggles == 0) return;
        hook.write_original(avr, addr, toggles);
        ctx->self->settle_inputs(avr, ctx->port);  // a toggled PORTxn of an input switches its pull-up
    }

    static void on_port_or_ddr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);
        auto* ctx = static_cast<PortHook*>(hook.context());
        ctx->self->settle_inputs(avr, ctx->port);
    }

    static void on_pud_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);
        auto* self = static_cast<PortPins*>(hook.context());
        for (auto& p : self->ports_) self->settle_inputs(avr, p.port);  // PUD switches every pull-up
    }

    // Every input of `port` that nothing outside drives: its pull-up level, or floating (0).
    void settle_inputs(avr_t* avr, avr_ioport_t* port) const {
        const bool pud = pud_register_ != 0 && (avr->data[pud_register_] & pud_mask_) != 0;
        const std::uint8_t ddr = avr->data[port->r_ddr], out = avr->data[port->r_port];
        const std::uint8_t undriven = static_cast<std::uint8_t>(~ddr & ~port->external.pull_mask);
        for (int bit = 0; bit < 8; ++bit) {
            const std::uint8_t mask = static_cast<std::uint8_t>(1u << bit);
            if ((undriven & mask) == 0) continue;
            const std::uint32_t level = (out & mask) != 0 && !pud ? 1 : 0;
            avr_irq_t* irq = port->io.irq + bit;
            if ((irq->value & 0xFF) != level) avr_raise_irq(irq, level);
        }
    }

    static void on_reset(avr_io_t* io) {
        PortPins* self = FixState<PortPins>::find(io);
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
    avr_io_addr_t pud_register_ = 0;
    std::uint8_t pud_mask_ = 0;
    std::vector<Port> ports_;
    std::vector<std::unique_ptr<PortHook>> hook_contexts_;
    std::vector<std::unique_ptr<IoWriteHook>> pin_hooks_;
};

}  // namespace

std::unique_ptr<Fix> install_port_pins(avr_t* avr) { return std::make_unique<PortPins>(avr); }

}  // namespace avrbench
