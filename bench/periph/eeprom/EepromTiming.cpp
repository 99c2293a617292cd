// EEPROM access timing (ATmega328P §8.4 "EEPROM Data Memory", §8.6.3 EECR,
// Table 8-2; ATmega2560 §8.3, §8.6.3, Table 8-1; ATmega32 "EEPROM Data
// Memory", Table 1).
//
// simavr 1.6 writes the byte at once and clears EEPE in the same instruction,
// so a firmware that waits for EEPE before its next write (avr-libc's
// eeprom_write_*) never waits; it ignores EEPM (erase-only / write-only); it
// raises EE_READY 3.4 ms after a write instead of "a constant interrupt when
// EEPE is cleared" while EERIE is set; and the CPU is not halted (2 cycles
// after EEPE, 4 after EERE). Here EECR writes are handled by the bench:
// EEPE stays set for the programming time of the mode (3.4 / 1.8 / 1.8 ms;
// m32: 8448 cycles of the 1 MHz RC oscillator), the byte changes when the
// programming ends, EERE while a write is in progress is ignored, and
// EE_READY is a level interrupt. The data lives in simavr's array (its
// ioctls still read and load it).
extern "C" {
#include <avr_eeprom.h>
#include <sim_cycle_timers.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class EepromTiming final : public Fix {
public:
    EepromTiming(avr_t* avr, avr_eeprom_t* ee) : avr_(avr), ee_(ee), facts_(part_facts(avr)) {
        hook_ = std::make_unique<IoWriteHook>(avr, ee->r_eecr, &on_write, this);
        avr_irq_register_notify(ee->ready.irq + AVR_INT_IRQ_PENDING, &on_ready_pending, this);
    }
    ~EepromTiming() override {
        hook_.reset();
        avr_irq_unregister_notify(ee_->ready.irq + AVR_INT_IRQ_PENDING, &on_ready_pending, this);
        avr_cycle_timer_cancel(avr_, &on_programmed, this);
        avr_cycle_timer_cancel(avr_, &on_mpe_window, this);
    }

private:
    std::uint16_t address() const {
        std::uint16_t a = avr_->data[ee_->r_eearl];
        if (ee_->r_eearh != 0) a = static_cast<std::uint16_t>(a | (avr_->data[ee_->r_eearh] << 8));
        return static_cast<std::uint16_t>(a & (ee_->size - 1));
    }

    // EE_READY: "a constant interrupt when EEPE is cleared" (while EERIE is set).
    void update_ready() {
        avr_int_vector_t* v = &ee_->ready;
        const bool request = avr_regbit_get(avr_, v->enable) && !busy_;
        if (request && !v->pending) {
            avr_raise_interrupt(avr_, v);
        } else if (!request && v->pending) {
            unpend_interrupt(avr_, v);
        }
    }

    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<EepromTiming*>(hook.context());
        avr_eeprom_t* ee = self->ee_;
        const std::uint8_t mpe = static_cast<std::uint8_t>(1u << ee->eempe.bit);
        const std::uint8_t pe = static_cast<std::uint8_t>(1u << ee->eepe.bit);
        const std::uint8_t re = static_cast<std::uint8_t>(1u << ee->eere.bit);
        const std::uint8_t old = avr->data[addr];
        std::uint8_t keep = static_cast<std::uint8_t>(old & (mpe | pe));  // hardware-controlled bits
        std::uint8_t v = static_cast<std::uint8_t>((value & ~(mpe | pe | re)) | keep);
        if (self->busy_ && ee->eepm[0].reg != 0) {
            // EEPM1:0 cannot change while EEPE is set.
            const std::uint8_t pm = static_cast<std::uint8_t>(0x3u << ee->eepm[0].bit);
            v = static_cast<std::uint8_t>((v & ~pm) | (old & pm));
        }
        avr->data[addr] = v;

        const bool write_pe = (value & pe) != 0;
        const bool write_mpe = (value & mpe) != 0;
        if (write_pe && (old & mpe) != 0 && !self->busy_) {
            // §8.4.1: EEPE written within four cycles of EEMPE starts the write;
            // "the CPU is halted for two cycles before the next instruction".
            unsigned mode = 0;
            if (ee->eepm[0].reg != 0) mode = avr_regbit_get_array(avr, ee->eepm, 2);
            self->start_write(mode);
            avr->data[addr] = static_cast<std::uint8_t>((avr->data[addr] | pe) & ~mpe);
            avr_cycle_timer_cancel(avr, &on_mpe_window, self);
            avr->cycle += 2;
        } else if (write_mpe && !write_pe) {
            avr->data[addr] |= mpe;  // cleared by hardware four cycles later
            avr_cycle_timer_register(avr, 4, &on_mpe_window, self);
        }
        if ((value & re) != 0 && !self->busy_) {
            // "When the EEPROM is read, the CPU is halted for four cycles."
            avr->data[ee->r_eedr] = ee->eeprom[self->address()];
            avr->cycle += 4;
        }
        self->update_ready();
    }

    void start_write(unsigned mode) {
        busy_ = true;
        address_ = address();
        data_ = avr_->data[ee_->r_eedr];
        mode_ = mode & 3;
        const std::uint32_t us = facts_.eeprom_write_us[mode_ < 3 ? mode_ : 0];
        const avr_cycle_count_t cycles = static_cast<avr_cycle_count_t>(us) * avr_->frequency / 1000000u;
        avr_cycle_timer_register(avr_, cycles, &on_programmed, this);
    }

    static avr_cycle_count_t on_mpe_window(avr_t* avr, avr_cycle_count_t, void* param) {
        auto* self = static_cast<EepromTiming*>(param);
        avr_regbit_clear(avr, self->ee_->eempe);
        return 0;
    }

    static avr_cycle_count_t on_programmed(avr_t* avr, avr_cycle_count_t, void* param) {
        auto* self = static_cast<EepromTiming*>(param);
        std::uint8_t& cell = self->ee_->eeprom[self->address_];
        switch (self->mode_) {
            case 1: cell = 0xFF; break;                                       // erase only
            case 2: cell = static_cast<std::uint8_t>(cell & self->data_); break;  // write only
            default: cell = self->data_; break;                              // erase and write
        }
        self->busy_ = false;
        avr_regbit_clear(avr, self->ee_->eepe);
        self->update_ready();
        return 0;
    }

    static void on_ready_pending(avr_irq_t*, std::uint32_t value, void* param) {
        if (value == 0) static_cast<EepromTiming*>(param)->update_ready();
    }

    avr_t* avr_;
    avr_eeprom_t* ee_;
    PartFacts facts_;
    std::unique_ptr<IoWriteHook> hook_;
    bool busy_ = false;
    std::uint16_t address_ = 0;
    std::uint8_t data_ = 0;
    unsigned mode_ = 0;
};

}  // namespace

std::unique_ptr<Fix> install_eeprom_timing(avr_t* avr) {
    avr_io_t* io = find_io_module(avr, "eeprom");
    if (io == nullptr) return nullptr;
    auto* ee = reinterpret_cast<avr_eeprom_t*>(io);
    if (ee->eeprom == nullptr || ee->size == 0) return nullptr;
    return std::make_unique<EepromTiming>(avr, ee);
}

}  // namespace avrbench
