#include "periph/spi/Spi.hpp"

#include <string_view>

extern "C" {
#include <avr_spi.h>
#include <sim_avr.h>
#include <sim_io.h>
#include <sim_irq.h>
}

namespace avrbench {

namespace {

// SPCR and SPSR bits, the same on the ATmega328P (§19.5.1, §19.5.2) and the
// ATmega2560 (§21.2.1, §21.2.2).
constexpr std::uint8_t kDord = 1u << 5, kMstr = 1u << 4, kCpol = 1u << 3, kCpha = 1u << 2;
constexpr std::uint8_t kSpi2x = 1u << 0;
constexpr unsigned kDivisors[4] = {4, 16, 64, 128};  // SPR1:0, Table 19-5 / 21-5

avr_io_t* spi_module(avr_t* avr) {
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind != nullptr && std::string_view(io->kind) == "spi") return io;
    }
    return nullptr;
}

}  // namespace

std::unique_ptr<Spi> Spi::install(avr_t* avr, std::function<bool()> miso_level) {
    avr_io_t* module = spi_module(avr);
    if (module == nullptr) return nullptr;
    return std::make_unique<Spi>(avr, module, std::move(miso_level));
}

Spi::Spi(avr_t* avr, avr_io_t* module, std::function<bool()> miso_level)
    : avr_(avr), module_(module), miso_level_(std::move(miso_level)) {
    avr_irq_register_notify(module_->irq + SPI_IRQ_OUTPUT, &on_output, this);
}

Spi::~Spi() { avr_irq_unregister_notify(module_->irq + SPI_IRQ_OUTPUT, &on_output, this); }

SpiTransfer Spi::transfer_of(std::uint8_t byte) const {
    const auto* p = reinterpret_cast<const avr_spi_t*>(module_);
    const std::uint8_t spcr = avr_->data[p->r_spcr], spsr = avr_->data[p->r_spsr];
    SpiTransfer t;
    t.mosi = byte;
    t.cpol = (spcr & kCpol) != 0;
    t.cpha = (spcr & kCpha) != 0;
    t.lsb_first = (spcr & kDord) != 0;
    const unsigned divisor = kDivisors[spcr & 0x03] / ((spsr & kSpi2x) != 0 ? 2 : 1);
    t.sck_hz = static_cast<double>(avr_->frequency) / divisor;
    t.cycle = avr_->cycle;
    return t;
}

void Spi::on_output(avr_irq_t*, std::uint32_t value, void* param) {
    auto* self = static_cast<Spi*>(param);
    if (self->slaves_.empty()) return;
    const auto* p = reinterpret_cast<const avr_spi_t*>(self->module_);
    // As a slave itself the MCU answers its master; parts are slaves only.
    if ((self->avr_->data[p->r_spcr] & kMstr) == 0) return;
    const SpiTransfer t = self->transfer_of(static_cast<std::uint8_t>(value));
    ++self->bytes_;
    std::optional<std::uint8_t> miso;
    std::vector<SpiSlave*> answered;
    for (SpiSlave* s : self->slaves_) {
        if (auto reply = s->exchange(t)) {
            if (!miso) miso = reply;
            answered.push_back(s);
        }
    }
    if (answered.size() > 1) {
        for (SpiSlave* s : answered) {
            std::string others;
            for (const SpiSlave* o : answered) {
                if (o != s) others += (others.empty() ? "" : ", ") + o->spi_name();
            }
            s->on_bus_contention(others, t.cycle);
        }
    }
    if (!miso && self->miso_level_) miso = self->miso_level_() ? 0xFF : 0x00;  // nobody drives MISO
    if (miso) avr_raise_irq(self->module_->irq + SPI_IRQ_INPUT, *miso);
}

}  // namespace avrbench
