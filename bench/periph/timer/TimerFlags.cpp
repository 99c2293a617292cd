// Timer interrupt flags and enables (ATmega328P §15.9.7, §16.11.9, §18.11.7
// TIFRn; §8.5 "I/O Memory"; ATmega2560 §16.10.7, §17.11 TIFRn, §8.4;
// ATmega32 "TIFR"):
//  - a flag is cleared by writing a logic one to it; writing zero leaves it
//    alone. simavr 1.6 ignores the value written and clears every flag of the
//    timer that is set: `TIFR1 = _BV(OCF1B)` also clears OCF1A and TOV1.
//  - on the 328P and 2560 "the CBI and SBI instructions will only operate on
//    the specified bit": SBI TIFR1,TOV1 clears TOV1 only, CBI clears nothing.
//    simavr performs them as a read-modify-write of the whole register (and
//    then clears everything anyway). The ATmega32's SBI/CBI do rewrite the
//    whole register (its datasheet says so), but its TIFR is out of their reach.
//  - a flag set while its interrupt is disabled raises the interrupt as soon
//    as the enable bit is written (§7.7: the flag "will be remembered until
//    the interrupt is enabled"). simavr only queues an interrupt that is
//    enabled when the flag is set, so enabling TIMSK1.OCIE1A after OCF1A was
//    set never runs the vector.
// Works with simavr's own timers and with the timer model alike.
#include <string_view>
#include <vector>

extern "C" {
#include <avr_timer.h>
#include <sim_interrupts.h>
#include <sim_regbit.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class TimerFlags final : public Fix {
public:
    explicit TimerFlags(avr_t* avr) : single_bit_(part_facts(avr).sbi_single_bit) {
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "timer") continue;
            auto* t = reinterpret_cast<avr_timer_t*>(io);
            add(&t->overflow);
            add(&t->icr);
            for (auto& c : t->comp) add(&c.interrupt);
        }
        for (auto& r : flag_registers_) {
            r.hook = std::make_unique<IoWriteHook>(avr, r.address, &on_flag_write, this);
        }
        for (avr_io_addr_t reg : enable_registers_) {
            enable_hooks_.push_back(std::make_unique<IoWriteHook>(avr, reg, &on_enable_write, this));
        }
    }

private:
    struct FlagRegister {
        avr_io_addr_t address = 0;
        std::vector<avr_int_vector_t*> vectors;
        std::unique_ptr<IoWriteHook> hook;
    };

    void add(avr_int_vector_t* v) {
        if (v->vector == 0 || v->raised.reg == 0) return;
        FlagRegister* reg = nullptr;
        for (auto& r : flag_registers_) {
            if (r.address == v->raised.reg) reg = &r;
        }
        if (reg == nullptr) {
            flag_registers_.emplace_back();
            reg = &flag_registers_.back();
            reg->address = static_cast<avr_io_addr_t>(v->raised.reg);
        }
        reg->vectors.push_back(v);
        if (v->enable.reg == 0) return;
        for (avr_io_addr_t e : enable_registers_) {
            if (e == v->enable.reg) return;
        }
        enable_registers_.push_back(static_cast<avr_io_addr_t>(v->enable.reg));
    }

    static void on_flag_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<TimerFlags*>(hook.context());
        const std::uint8_t ones = self->single_bit_ ? single_bit_write_value(avr, addr, value) : value;
        for (const auto& r : self->flag_registers_) {
            if (r.address != addr) continue;
            for (avr_int_vector_t* v : r.vectors) {
                const unsigned mask = static_cast<unsigned>(v->raised.mask) << v->raised.bit;
                if ((ones & mask) == 0 || avr_regbit_get(avr, v->raised) == 0) continue;
                avr_clear_interrupt(avr, v);  // flag and pending; tells the flag's listeners
                unpend_interrupt(avr, v);     // and simavr's pending FIFO
            }
        }
        // Nothing is stored: the flags only change by hardware and by the ones written.
    }

    static void on_enable_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);
        sync_enables(avr, addr);
    }

    bool single_bit_;
    std::vector<FlagRegister> flag_registers_;
    std::vector<avr_io_addr_t> enable_registers_;
    std::vector<std::unique_ptr<IoWriteHook>> enable_hooks_;
};

}  // namespace

std::unique_ptr<Fix> install_timer_flags(avr_t* avr) { return std::make_unique<TimerFlags>(avr); }

}  // namespace avrbench
