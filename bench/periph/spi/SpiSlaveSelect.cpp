// The SS pin of an SPI master (ATmega328P §19.3.2 "SS Pin Functionality",
// ATmega2560 §21.3.2): an input SS driven low while the SPI is master makes
// it a slave - MSTR cleared, SPIF set, the interrupt if enabled - so two
// masters never drive the bus at once. simavr 1.6 (Debian) ignores SS in
// master mode. Here the bench watches the pin (a level change, as wiring and
// tests drive it) and SPCR writes (MSTR set while an input SS is already low).
// An output SS is a plain pin, as the datasheet says.
extern "C" {
#include <avr_ioport.h>
#include <avr_spi.h>
#include <sim_interrupts.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include <memory>
#include <string_view>
#include <vector>

#include "core/IoHook.hpp"
#include "periph/Fixes.hpp"

namespace avrbench {
namespace {

constexpr std::uint8_t kSpcrSpe = 1u << 6, kSpcrMstr = 1u << 4;

// Where SS is: 328P Table 14-3 (PB2), 2560 Table 13-6 (PB0), ATmega32/644/1284 (PB4).
int slave_select_bit(std::string_view mcu) {
    if (mcu.find("2560") != std::string_view::npos || mcu.find("1280") != std::string_view::npos ||
        mcu.find("2561") != std::string_view::npos || mcu.find("1281") != std::string_view::npos) {
        return 0;
    }
    if (mcu == "atmega32" || mcu == "atmega16" || mcu.find("644") != std::string_view::npos ||
        mcu.find("1284") != std::string_view::npos || mcu.find("164") != std::string_view::npos ||
        mcu.find("324") != std::string_view::npos) {
        return 4;
    }
    return 2;
}

class SpiSlaveSelect final : public Fix {
public:
    SpiSlaveSelect(avr_t* avr, avr_spi_t* spi, avr_ioport_t* port, int bit)
        : avr_(avr), spi_(spi), port_(port), bit_(bit),
          pin_irq_(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port->name), bit)) {
        if (pin_irq_ != nullptr) avr_irq_register_notify(pin_irq_, &on_pin, this);
        spcr_hook_ = std::make_unique<IoWriteHook>(avr, spi->r_spcr, &on_spcr_write, this);
    }
    ~SpiSlaveSelect() override {
        spcr_hook_.reset();
        if (pin_irq_ != nullptr) avr_irq_unregister_notify(pin_irq_, &on_pin, this);
    }

private:
    static void on_pin(avr_irq_t*, std::uint32_t value, void* param) {
        if (value == 0) static_cast<SpiSlaveSelect*>(param)->check(false);
    }
    static void on_spcr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);
        auto* self = static_cast<SpiSlaveSelect*>(hook.context());
        // The pin's level (its IRQ's value: what drives it, or its pull-up),
        // not a PINx read, which would count as the firmware reading it.
        self->check(self->pin_irq_ == nullptr || (self->pin_irq_->value & 0xff) != 0);
    }

    void check(bool ss_level) {
        std::uint8_t& spcr = avr_->data[spi_->r_spcr];
        if ((spcr & (kSpcrSpe | kSpcrMstr)) != (kSpcrSpe | kSpcrMstr)) return;
        const std::uint8_t mask = static_cast<std::uint8_t>(1u << bit_);
        if ((avr_->data[port_->r_ddr] & mask) != 0 || ss_level) return;
        spcr = static_cast<std::uint8_t>(spcr & ~kSpcrMstr);
        avr_raise_interrupt(avr_, &spi_->spi);
    }

    avr_t* avr_;
    avr_spi_t* spi_;
    avr_ioport_t* port_;
    int bit_;
    avr_irq_t* pin_irq_;
    std::unique_ptr<IoWriteHook> spcr_hook_;
};

class SpiSlaveSelectFix final : public Fix {
public:
    explicit SpiSlaveSelectFix(avr_t* avr) {
        avr_ioport_t* port_b = nullptr;
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind != nullptr && std::string_view(io->kind) == "port" &&
                reinterpret_cast<avr_ioport_t*>(io)->name == 'B') {
                port_b = reinterpret_cast<avr_ioport_t*>(io);
            }
        }
        if (port_b == nullptr) return;
        const int bit = slave_select_bit(avr->mmcu != nullptr ? avr->mmcu : "");
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "spi") continue;
            fixes_.push_back(std::make_unique<SpiSlaveSelect>(avr, reinterpret_cast<avr_spi_t*>(io), port_b, bit));
        }
    }

private:
    std::vector<std::unique_ptr<SpiSlaveSelect>> fixes_;
};

}  // namespace

std::unique_ptr<Fix> install_spi_slave_select(avr_t* avr) { return std::make_unique<SpiSlaveSelectFix>(avr); }

}  // namespace avrbench
