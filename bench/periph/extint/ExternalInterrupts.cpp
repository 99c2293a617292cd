// External interrupts INTn and the pin-change flag register (ATmega328P §13,
// ATmega2560 §15, ATmega32 "External Interrupts").
//
// simavr 1.6's INTn module departs from the datasheet:
//  - low-level mode (ISCn1:0 = 00, the reset default) with the pin low starts
//    a cycle timer that polls the pin every cycle, whether or not INTn is
//    enabled, and one more per falling edge: a firmware with step pins on
//    PD2/PD3 runs several times slower; it also sets INTFn, which §13.2.3
//    says always reads zero in level mode, and raises the interrupt only if
//    SREG.I happens to be set at the edge;
//  - writing a one to an INTFn/PCIFn flag (EIFR, PCIFR, GIFR) sets it instead
//    of clearing it, and does not cancel the pending interrupt;
//  - enabling INTn/PCIEn while its flag is set does not start the interrupt
//    (§7.7: the flag "will be set and remembered until the interrupt is enabled");
//  - INT0/INT1 edges are detected in every sleep mode; they need clk_IO, so
//    from the modes other than Idle only the level interrupt wakes the part
//    (§10.1 Table 10-1 note 3).
// Here the module's pin connection is cut and the bench evaluates the INTn
// lines itself: edges on pin changes, the level request on every change of the
// pin, EIMSK, EICRA and at the vector's entry (so a held level re-triggers
// after RETI plus one instruction). No polling.
#include <string_view>
#include <vector>

extern "C" {
#include <avr_extint.h>
#include <avr_ioport.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class ExternalInterrupts final : public Fix {
public:
    ExternalInterrupts(avr_t* avr, avr_extint_t* extint) : avr_(avr), extint_(extint), facts_(part_facts(avr)) {
        for (int i = 0; i < EXTINT_COUNT; ++i) {
            auto& e = extint->eint[i];
            if (e.port_ioctl == 0) continue;
            Line line;
            line.self = this;
            line.index = i;
            line.pin = avr_io_getirq(avr, e.port_ioctl, e.port_pin);
            line.has_level_mode = e.isc[1].reg != 0;
            if (line.pin == nullptr) continue;
            lines_.push_back(line);
        }
        for (auto& line : lines_) {
            line.level = (line.pin->value & 0xff) != 0;
            avr_irq_register_notify(line.pin, &on_pin, &line);
            avr_irq_register_notify(extint_->eint[line.index].vector.irq + AVR_INT_IRQ_PENDING, &on_vector_pending,
                                    &line);
        }
        disconnect_simavr();
        original_reset_ = extint_->io.reset;
        extint_->io.reset = &on_reset;
        FixState<ExternalInterrupts>::add(&extint_->io, this);

        // Registers: enables, sense control, flags (INTn), and PCICR/PCIFR.
        std::vector<avr_io_addr_t> enables, controls, flags;
        auto add = [](std::vector<avr_io_addr_t>& v, avr_io_addr_t a) {
            if (a == 0) return;
            for (auto x : v) if (x == a) return;
            v.push_back(a);
        };
        for (auto& line : lines_) {
            auto& e = extint_->eint[line.index];
            add(enables, e.vector.enable.reg);
            add(controls, e.isc[0].reg);
            add(controls, e.isc[1].reg);
            add(flags, e.vector.raised.reg);
        }
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "port") continue;
            auto* port = reinterpret_cast<avr_ioport_t*>(io);
            if (port->pcint.vector == 0) continue;
            add(enables, port->pcint.enable.reg);
            add(flags, port->pcint.raised.reg);
        }
        for (auto a : enables) hooks_.push_back(std::make_unique<IoWriteHook>(avr, a, &on_enable_write, this));
        for (auto a : controls) {
            bool also_enable = false;
            for (auto e : enables) also_enable = also_enable || e == a;
            if (!also_enable) hooks_.push_back(std::make_unique<IoWriteHook>(avr, a, &on_control_write, this));
        }
        for (auto& line : lines_) {
            for (const avr_regbit_t& isc : extint_->eint[line.index].isc) {
                if (isc.reg != 0) control_bits_.push_back({static_cast<avr_io_addr_t>(isc.reg), static_cast<std::uint8_t>(isc.mask << isc.bit)});
            }
        }
        for (auto a : flags) hooks_.push_back(std::make_unique<IoWriteHook>(avr, a, &on_flag_write, this));
        for (auto& line : lines_) update_level(line);
    }

    ~ExternalInterrupts() override {
        hooks_.clear();
        for (auto& line : lines_) {
            avr_irq_unregister_notify(line.pin, &on_pin, &line);
            avr_irq_unregister_notify(extint_->eint[line.index].vector.irq + AVR_INT_IRQ_PENDING, &on_vector_pending,
                                      &line);
        }
        extint_->io.reset = original_reset_;
        FixState<ExternalInterrupts>::remove(&extint_->io);
    }

private:
    struct Line {
        ExternalInterrupts* self = nullptr;
        int index = 0;
        avr_irq_t* pin = nullptr;
        bool has_level_mode = false;
        bool level = true;
    };

    void disconnect_simavr() {
        for (auto& line : lines_) {
            avr_unconnect_irq(line.pin, extint_->io.irq + line.index);
            extint_->eint[line.index].strict_lvl_trig = 0;
        }
    }

    // ISCn1:0 (or 2 + ISCn for the asynchronous edge-only lines such as
    // INT2 on the ATmega32): 0 low level, 1 any change, 2 falling, 3 rising.
    int mode(const Line& line) const {
        auto& e = extint_->eint[line.index];
        if (!line.has_level_mode) return 2 + avr_regbit_get(avr_, e.isc[0]);
        return avr_regbit_get(avr_, e.isc[0]) | (avr_regbit_get(avr_, e.isc[1]) << 1);
    }

    // Level mode: the request is "pin low and INTn enabled"; INTFn stays 0.
    void update_level(Line& line) {
        if (!line.has_level_mode) return;
        auto& v = extint_->eint[line.index].vector;
        if (mode(line) != 0) return;
        const bool request = !line.level && avr_regbit_get(avr_, v.enable) != 0;
        if (request && !v.pending) {
            avr_raise_interrupt(avr_, &v);
        } else if (!request && v.pending) {
            unpend_interrupt(avr_, &v);
        }
        if (v.raised.reg != 0) avr_regbit_clear(avr_, v.raised);
    }

    bool edge_detector_clocked(const Line& line) const {
        if (avr_->state != cpu_Sleeping) return true;
        if ((facts_.synchronous_int_mask & (1u << line.index)) == 0) return true;
        return sleep_mode(avr_, facts_) == kSleepIdle;
    }

    static void on_pin(avr_irq_t*, std::uint32_t value, void* param) {
        auto& line = *static_cast<Line*>(param);
        ExternalInterrupts* self = line.self;
        const bool level = (value & 0xff) != 0;
        const bool up = level && !line.level;
        const bool down = !level && line.level;
        line.level = level;
        if (!up && !down) return;
        const int m = self->mode(line);
        if (m == 0) {
            self->update_level(line);
            return;
        }
        const bool fire = m == 1 || (m == 2 && down) || (m == 3 && up);
        if (fire && self->edge_detector_clocked(line)) avr_raise_interrupt(self->avr_, &self->extint_->eint[line.index].vector);
    }

    // The vector stopped pending (taken, or cleared): a held low level asks again.
    static void on_vector_pending(avr_irq_t*, std::uint32_t value, void* param) {
        auto& line = *static_cast<Line*>(param);
        if (value == 0) line.self->update_level(line);
    }

    static void on_enable_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<ExternalInterrupts*>(hook.context());
        hook.write_original(avr, addr, value);
        sync_enables(avr, addr);
        for (auto& line : self->lines_) self->update_level(line);
    }

    // MCUCR on the ATmega32 holds the sleep bits too: written on every
    // sleep. Only a change of the sense control bits can change a request;
    // every other change of a level line's request (pin, enable, vector
    // taken or cleared, reset) is followed at once by its own handler.
    static void on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<ExternalInterrupts*>(hook.context());
        const std::uint8_t before = avr->data[addr];
        hook.write_original(avr, addr, value);
        std::uint8_t sense_bits = 0;
        for (const ControlBits& c : self->control_bits_) {
            if (c.reg == addr) sense_bits |= c.mask;
        }
        if (((before ^ avr->data[addr]) & sense_bits) == 0) return;
        for (auto& line : self->lines_) self->update_level(line);
    }

    // EIFR / PCIFR / GIFR: "the flag can be cleared by writing a logical one to it".
    static void on_flag_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<ExternalInterrupts*>(hook.context());
        const std::uint8_t ones = self->facts_.sbi_single_bit ? single_bit_write_value(avr, addr, value) : value;
        for (int i = 0; i < avr->interrupts.vector_count; ++i) {
            avr_int_vector_t* v = avr->interrupts.vector[i];
            if (v->raised.reg != addr) continue;
            if ((ones & (v->raised.mask << v->raised.bit)) == 0) continue;
            if (v->pending) unpend_interrupt(avr, v);
            avr_regbit_clear(avr, v->raised);
            avr_raise_irq(v->irq + AVR_INT_IRQ_PENDING, 0);  // as simavr's own flag clears do
        }
    }

    static void on_reset(avr_io_t* io) {
        ExternalInterrupts* self = FixState<ExternalInterrupts>::find(io);
        self->original_reset_(io);  // re-registers its notify and reconnects the pins
        self->disconnect_simavr();
        for (auto& line : self->lines_) {
            line.level = (line.pin->value & 0xff) != 0;
            self->update_level(line);
        }
    }

    avr_t* avr_;
    avr_extint_t* extint_;
    PartFacts facts_;
    std::vector<Line> lines_;
    struct ControlBits {
        avr_io_addr_t reg;
        std::uint8_t mask;  // ISCn bits in place
    };
    std::vector<ControlBits> control_bits_;
    std::vector<std::unique_ptr<IoWriteHook>> hooks_;
    void (*original_reset_)(avr_io_t*) = nullptr;
};

}  // namespace

std::unique_ptr<Fix> install_external_interrupts(avr_t* avr) {
    avr_io_t* io = find_io_module(avr, "extint");
    if (io == nullptr) return nullptr;
    return std::make_unique<ExternalInterrupts>(avr, reinterpret_cast<avr_extint_t*>(io));
}

}  // namespace avrbench
