// The SPI master of one MCU as the bench's SPI slaves see it: each byte the
// firmware shifts out, with the mode and clock it was shifted at, offered to
// the slaves on the bus; the selected one's reply is what the firmware reads
// back from SPDR.
//
// simavr's SPI module moves whole bytes: writing SPDR in master mode raises
// SPIF (and SPI_IRQ_OUTPUT with the byte) 8 SCK periods later, f_osc/4..128,
// /2 with SPI2X (ATmega328P §19.5 Table 19-5, ATmega2560 §21.2.1 Table 21-5);
// a byte raised on SPI_IRQ_INPUT then becomes SPDR. This class answers that
// IRQ from the slaves, at the cycle the transfer ends. A byte no slave
// answers reads the MISO line's level on every bit (a pull-up: 0xFF; a
// floating line, the bench's low: 0x00). Without slaves on the bus it does
// nothing, and SPDR keeps what simavr leaves there (its input register).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;
struct avr_io_t;

namespace avrbench {

// How the master shifted a byte (SPCR/SPSR at the end of the transfer).
struct SpiTransfer {
    std::uint8_t mosi = 0;
    bool cpol = false;       // SPCR.CPOL: SCK idles high
    bool cpha = false;       // SPCR.CPHA: data sampled on the trailing edge
    bool lsb_first = false;  // SPCR.DORD
    double sck_hz = 0;       // f_osc / (4, 16, 64, 128), doubled by SPI2X
    Cycle cycle = 0;  // when the transfer ended (SPIF)
    // SPI mode 0..3 (CPOL * 2 + CPHA), the name datasheets use.
    int mode() const { return (cpol ? 2 : 0) + (cpha ? 1 : 0); }
};

// A device on the bus. exchange() is asked for every byte; a slave that is
// not selected (its chip select high) returns nothing and ignores the byte.
class SpiSlave {
public:
    virtual std::optional<std::uint8_t> exchange(const SpiTransfer& transfer) = 0;
    // For findings about the bus: "x_driver".
    virtual const std::string& spi_name() const = 0;
    // Another slave answered the same byte (both were selected): their MISO
    // outputs fought. `others` names them.
    virtual void on_bus_contention(const std::string& others, Cycle cycle) = 0;

protected:
    ~SpiSlave() = default;
};

class Spi {
public:
    // nullptr when the core has no SPI module. `miso_level`: the level of the
    // MCU's MISO pin as its net has it.
    static std::unique_ptr<Spi> install(avr_t* avr, std::function<bool()> miso_level);
    Spi(avr_t* avr, avr_io_t* module, std::function<bool()> miso_level);
    ~Spi();
    Spi(const Spi&) = delete;
    Spi& operator=(const Spi&) = delete;

    void attach(SpiSlave& slave) { slaves_.push_back(&slave); }
    std::uint64_t bytes_exchanged() const { return bytes_; }

private:
    static void on_output(avr_irq_t* irq, std::uint32_t value, void* param);
    SpiTransfer transfer_of(std::uint8_t byte) const;

    avr_t* avr_;
    avr_io_t* module_;
    std::vector<SpiSlave*> slaves_;
    std::function<bool()> miso_level_;
    std::uint64_t bytes_ = 0;
};

}  // namespace avrbench
