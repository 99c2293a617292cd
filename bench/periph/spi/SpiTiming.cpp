// SPI master transfer time and write collision (ATmega328P §19.5, Table
// 19-5, §19.5.2; ATmega2560 §21.2, Table 21-5, §21.2.2).
//
// simavr 1.6 (Debian) ends every master transfer 100 us after the SPDR write,
// whatever SPR1:0 and SPI2X say (a byte at f_osc/4 takes 32 cycles, not
// 1600), and takes an SPDR write during a transfer as a new transfer. Here
// SPDR writes are handled by the bench: the transfer ends 8 SCK periods later
// (f_osc/4, 16, 64, 128; half that with SPI2X), SPIF is raised and the byte
// goes out on SPI_IRQ_OUTPUT as simavr's own module would; a write during a
// transfer sets WCOL and is ignored. Reading SPDR still clears SPIF (and
// WCOL here), simavr's read hook; the datasheet first wants an SPSR read,
// which every polling loop does.
extern "C" {
#include <avr_spi.h>
#include <sim_cycle_timers.h>
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

constexpr std::uint8_t kSpe = 1u << 6, kMstr = 1u << 4;
constexpr std::uint8_t kWcol = 1u << 6, kSpi2x = 1u << 0;
constexpr unsigned kDivisors[4] = {4, 16, 64, 128};

class SpiTiming final : public Fix {
public:
    SpiTiming(avr_t* avr, avr_spi_t* spi) : avr_(avr), spi_(spi) {
        hook_ = std::make_unique<IoWriteHook>(avr, spi->r_spdr, &on_spdr_write, this);
    }
    ~SpiTiming() override {
        hook_.reset();
        avr_cycle_timer_cancel(avr_, &on_transfer_end, this);
    }

private:
    static void on_spdr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<SpiTiming*>(hook.context());
        avr_spi_t* p = self->spi_;
        if (self->in_transfer_) {
            avr->data[p->r_spsr] |= kWcol;  // the transfer goes on with the old byte
            return;
        }
        // A write clears SPIF (as simavr's handler does) and starts a transfer in master mode.
        avr_regbit_clear(avr, p->spi.raised);
        avr->data[p->r_spsr] &= static_cast<std::uint8_t>(~kWcol);
        avr->data[addr] = value;
        const std::uint8_t spcr = avr->data[p->r_spcr];
        if ((spcr & kSpe) == 0 || (spcr & kMstr) == 0) return;
        unsigned divisor = kDivisors[spcr & 0x03];
        if ((avr->data[p->r_spsr] & kSpi2x) != 0) divisor /= 2;
        self->in_transfer_ = true;
        avr_cycle_timer_register(avr, 8 * divisor, &on_transfer_end, self);
    }

    static avr_cycle_count_t on_transfer_end(avr_t* avr, avr_cycle_count_t, void* param) {
        auto* self = static_cast<SpiTiming*>(param);
        avr_spi_t* p = self->spi_;
        self->in_transfer_ = false;
        if ((avr->data[p->r_spcr] & kSpe) != 0 && (avr->data[p->r_spcr] & kMstr) != 0) {
            avr_raise_interrupt(avr, &p->spi);
            avr_raise_irq(p->io.irq + SPI_IRQ_OUTPUT, avr->data[p->r_spdr]);
        }
        return 0;
    }

    avr_t* avr_;
    avr_spi_t* spi_;
    std::unique_ptr<IoWriteHook> hook_;
    bool in_transfer_ = false;
};

class SpiTimingFix final : public Fix {
public:
    explicit SpiTimingFix(avr_t* avr) {
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "spi") continue;
            fixes_.push_back(std::make_unique<SpiTiming>(avr, reinterpret_cast<avr_spi_t*>(io)));
        }
    }

private:
    std::vector<std::unique_ptr<SpiTiming>> fixes_;
};

}  // namespace

std::unique_ptr<Fix> install_spi_timing(avr_t* avr) { return std::make_unique<SpiTimingFix>(avr); }

}  // namespace avrbench
