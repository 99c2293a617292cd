// A part on an MCU's SPI bus: its SCK, MOSI and MISO pins on the nets of the
// MCU's SPI pins (periph/ports/McuPins.hpp spi_pins), its chip select on any
// pin, and the bytes from the MCU's master (periph/spi/Spi.hpp). What every
// SPI slave checks of its master: the mode, the bit order, the clock.
#pragma once

#include <cstddef>
#include <string>

#include "core/Finding.hpp"
#include "periph/spi/Spi.hpp"

namespace avrbench {

class Part;

// What a slave's datasheet allows.
struct SpiLimits {
    int mode = 0;            // CPOL * 2 + CPHA
    bool lsb_first = false;  // the bit order
    double max_sck_hz = 0;   // the fastest clock
    std::string source;      // the datasheet section, for the finding's text
};

// The misuse findings every SPI slave reports.
extern const FindingKind kSpiModeMismatch;   // spi-mode-mismatch
extern const FindingKind kSpiClockTooFast;   // spi-clock-too-fast
extern const FindingKind kSpiBusContention;  // spi-bus-contention

// Joins `slave` to the SPI master of `part`'s MCU when its pins `sck`,
// `mosi` and `miso` share nets with that MCU's SCK, MOSI and MISO; BadInput
// (one line, naming the pin) otherwise.
void attach_spi_slave(Part& part, std::size_t sck, std::size_t mosi, std::size_t miso, SpiSlave& slave);

// The spi-bus-contention finding's text for a slave selected together with
// `others` (each slave reports it once: the bus stays wrong until the
// firmware fixes its chip selects).
std::string spi_contention_detail(const std::string& others);

// "" when `t` was shifted in the mode and bit order `limits` gives, else why
// not (a kSpiModeMismatch finding's text).
std::string spi_mode_problem(const SpiTransfer& t, const SpiLimits& limits);
// "" when `t`'s clock is within `limits`, else why not (kSpiClockTooFast).
std::string spi_clock_problem(const SpiTransfer& t, const SpiLimits& limits);

}  // namespace avrbench
